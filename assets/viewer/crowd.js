// bmlr view: crowds. A page of more characters than the frames file's lines can carry has its
// frames packed (pack.rs): per frame, each character's root as 7 floats, then the rotations of
// the joints that move as 16-bit integers; the rest of the joints once per character. Its
// characters are drawn as one crowd: the mannequin's boxes as two instanced meshes (clothes,
// skin) for all of them, placed by forward kinematics here every frame, so hundreds cost two
// draw calls instead of thousands. Up to 100 characters are drawn as people instead
// (avatars.js: the default avatar, one skinned copy each sharing its geometry), their bones
// set here. Crowd pages draw no faces.
'use strict';

/** The packed frames of `packed` for a skeleton of `joints`: pose(i, k, out) writes frame i of
 *  character k as root x y z, rotation x y z w, then x y z w per joint. */
class BmlrPackedFrames {
  constructor(packed, joints) {
    const bytes = (b64) => {
      const s = atob(b64);
      const out = new Uint8Array(s.length);
      for (let i = 0; i < s.length; i++) out[i] = s.charCodeAt(i);
      return out.buffer;
    };
    this.characters = packed.characters;
    this.times = packed.times;
    this.moving = packed.moving;
    this.joints = joints.length;
    this.roots = new Float32Array(bytes(packed.roots));
    this.rotations = new Int16Array(bytes(packed.rotations));
    // each character's joints at their one rotation (the moving ones are overwritten)
    this.still = packed.still.map((list) => {
      const pose = new Float32Array(7 + 4 * joints.length);
      list.forEach((q, j) => pose.set(q, 7 + 4 * j));
      return pose;
    });
  }

  pose(i, k, out) {
    const n = this.characters.length;
    const m = this.moving.length;
    out.set(this.still[k]);
    out.set(this.roots.subarray((i * n + k) * 7, (i * n + k + 1) * 7), 0);
    const base = (i * n + k) * m * 4;
    for (let a = 0; a < m; a++) {
      const at = 7 + 4 * this.moving[a];
      for (let c = 0; c < 4; c++) out[at + c] = this.rotations[base + 4 * a + c] / 32767;
    }
    return out;
  }

  /** Where every character stands over the clip: x0 z0 x1 z1. */
  bounds() {
    let [x0, z0, x1, z1] = [Infinity, Infinity, -Infinity, -Infinity];
    for (let r = 0; r < this.roots.length; r += 7) {
      [x0, z0] = [Math.min(x0, this.roots[r]), Math.min(z0, this.roots[r + 2])];
      [x1, z1] = [Math.max(x1, this.roots[r]), Math.max(z1, this.roots[r + 2])];
    }
    return { x0, z0, x1, z1 };
  }
}

/** The crowd's figures: the mannequin's boxes (`segments`) on every character, as instances. */
class BmlrCrowd {
  constructor(THREE, scene, joints, segments, materials, count) {
    this.THREE = THREE;
    this.joints = joints;
    this.count = count;
    const index = new Map(joints.map((j, i) => [j.name, i]));
    this.parents = joints.map((j) => (j.parent === null ? -1 : index.get(j.parent)));
    this.offsets = joints.map((j) => new THREE.Vector3().fromArray(j.offset));
    const rest = [];
    joints.forEach((j, i) => {
      const p = this.offsets[i].clone();
      if (this.parents[i] >= 0) p.add(rest[this.parents[i]]);
      rest.push(p);
    });
    // each box in its joint's frame: a unit cube scaled, turned and moved
    const up = new THREE.Vector3(0, 1, 0);
    this.boxes = [[], []];
    for (const s of segments) {
      const a = new THREE.Vector3().fromArray(s.from);
      const b = new THREE.Vector3().fromArray(s.to);
      const length = Math.max(a.distanceTo(b), 0.01);
      const turn = new THREE.Quaternion();
      if (length > 0.01) turn.setFromUnitVectors(up, b.clone().sub(a).normalize());
      const at = a.clone().add(b).multiplyScalar(0.5).sub(rest[s.joint]);
      const local = new THREE.Matrix4().compose(at, turn, new THREE.Vector3(s.width, length, s.width));
      this.boxes[s.skin ? 1 : 0].push({ joint: s.joint, local });
    }
    const cube = new THREE.BoxGeometry(1, 1, 1);
    this.meshes = this.boxes.map((list, m) => {
      const mesh = new THREE.InstancedMesh(cube, materials[m], Math.max(list.length * count, 1));
      mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
      // the instances move all over the world: the mesh's own bounds would cull them wrongly
      mesh.frustumCulled = false;
      scene.add(mesh);
      return mesh;
    });
    this.worldAt = joints.map(() => new THREE.Vector3());
    this.worldTurn = joints.map(() => new THREE.Quaternion());
    this.local = new THREE.Quaternion();
    this.joint = new THREE.Matrix4();
    this.box = new THREE.Matrix4();
    this.one = new THREE.Vector3(1, 1, 1);
    this.step = new THREE.Vector3();
  }

  /** Puts character k's boxes (or, drawn as people, its avatar's bones) where `pose` (root,
   *  rotation, joint rotations) has them. */
  place(k, pose) {
    if (this.people) {
      this.people[k].forEach((bone, j) => {
        if (!bone) return;
        if (this.parents[j] < 0) {
          bone.position.set(pose[0], pose[1], pose[2]);
          bone.quaternion.fromArray(pose, 3);
        } else {
          bone.quaternion.fromArray(pose, 7 + 4 * j);
        }
      });
      return;
    }
    const [at, turn] = [this.worldAt, this.worldTurn];
    for (let j = 0; j < this.joints.length; j++) {
      const p = this.parents[j];
      if (p < 0) {
        at[j].set(pose[0], pose[1], pose[2]);
        turn[j].fromArray(pose, 3);
        continue;
      }
      this.step.copy(this.offsets[j]).applyQuaternion(turn[p]);
      at[j].copy(at[p]).add(this.step);
      turn[j].copy(turn[p]).multiply(this.local.fromArray(pose, 7 + 4 * j));
    }
    this.boxes.forEach((list, m) => {
      list.forEach((b, s) => {
        this.joint.compose(at[b.joint], turn[b.joint], this.one);
        this.box.multiplyMatrices(this.joint, b.local);
        this.meshes[m].setMatrixAt(k * list.length + s, this.box);
      });
    });
  }

  /** Done placing this frame's characters. */
  placed() {
    for (const mesh of this.meshes) mesh.instanceMatrix.needsUpdate = true;
  }
}
