"""The Python package against the command line: the same feedback and the same poses for
fixtures/examples/welcome.xml at 60 Hz, errors as exceptions, threads, the helpers.

The comparison with `bmlr run` needs the command: set BMLR to its path (.ci/run does)."""

import json
import os
import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import bmlr

ROOT = Path(__file__).resolve().parents[3]
WELCOME = ROOT / "fixtures" / "examples" / "welcome.xml"


def progress(messages):
    return [
        (m["feedback"], m["id"], m.get("time"), m.get("globalTime"))
        for m in messages
        if m["feedback"] in ("blockProgress", "syncPointProgress")
    ]


def realize(realizer, text, fps=60.0):
    """Feedback and default-character poses of `text` ticked at `fps` until nothing is due."""
    realizer.perform(text)
    feedback, poses, k = [], {}, 0
    while True:
        t = k / fps
        feedback += realizer.tick(t)
        poses[round(t, 6)] = realizer.pose()
        if realizer.next_event() is None:
            return feedback, poses
        k += 1


def test_feedback_and_poses_equal_bmlr_run(tmp_path):
    command = os.environ.get("BMLR")
    if not command:
        pytest.skip("set BMLR to the bmlr command to compare with `bmlr run`")
    frames_file = tmp_path / "frames.jsonl"
    out = subprocess.run(
        [command, "run", "--format", "jsonl", "--frames", str(frames_file), str(WELCOME)],
        check=True, capture_output=True, text=True,
    ).stdout
    expected = progress(json.loads(line) for line in out.splitlines())
    feedback, poses = realize(bmlr.Realizer(), WELCOME.read_text())
    assert progress(feedback) == expected and len(expected) == 19
    lines = frames_file.read_text().splitlines()
    names = [j["name"] for j in json.loads(lines[0])["skeleton"]["joints"]]
    assert names == bmlr.Realizer().joint_names
    compared = 0
    for line in lines[1:]:
        frame = json.loads(line)
        pose = poses.get(round(frame["time"], 6))
        if pose is None:
            continue
        joints = frame["characters"][""]["joints"]
        want = np.array([joints[n] for n in names], dtype=np.float64)
        assert np.abs(pose - want).max() <= 1e-6
        compared += 1
    assert compared >= len(lines) - 2


def test_a_body_a_root_and_a_face_in_every_frame():
    r = bmlr.Realizer(idle=False)
    r.perform(WELCOME.read_text())
    widest = 0.0
    for k in range(120):
        r.tick(k / 60)
        pose = r.pose()
        assert pose.shape == (57, 4) and pose.dtype == np.float32
        assert np.allclose(np.linalg.norm(pose, axis=1), 1.0, atol=1e-5)
        widest = max(widest, r.morphs()["jawOpen"])
    position, rotation = r.root()
    assert position.shape == (3,) and rotation.shape == (4,)
    assert abs(position[1] - 0.95) < 0.05
    assert widest > 0.1, "the jaw opens while speaking"
    assert len(r.morph_names) == 52 and list(r.morphs()) == r.morph_names


def test_bad_input_raises_readable_errors():
    r = bmlr.Realizer()
    with pytest.raises(bmlr.BmlError, match="wrong-root"):
        r.perform('<bml id="broken"><gesture')
    with pytest.raises(RuntimeError, match="tick"):
        r.pose()
    r.tick(0.0)
    with pytest.raises(KeyError, match="nobody"):
        r.pose("nobody")
    with pytest.raises(ValueError, match="unknown option|tts"):
        bmlr.Realizer(tts="espeak")
    with pytest.raises(ValueError):
        r.tick(float("nan"))
    problems = bmlr.validate('<bml id="broken"><gesture')
    assert problems and problems[0]["severity"] == "error" and problems[0]["line"] == 1
    assert bmlr.validate(WELCOME.read_text()) == []


def test_a_realizer_used_from_other_threads():
    r = bmlr.Realizer()
    r.perform(WELCOME.read_text())
    errors = []

    def work(offset):
        try:
            for k in range(60):
                r.tick((offset + k) / 60)
                r.pose()
        except BaseException as e:  # a PanicException is a BaseException
            errors.append(e)

    threads = [threading.Thread(target=work, args=(60 * i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []


def test_the_world_places_characters():
    world = {"characters": {"Alice": {"position": [1.0, 0.0, 2.0]}}}
    r = bmlr.Realizer(world=world)
    r.perform(
        '<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a" characterId="Alice">'
        '<head id="n" lexeme="NOD"/></bml>'
    )
    r.tick(0.1)
    assert "Alice" in r.characters()
    position, _ = r.root("Alice")
    assert abs(position[0] - 1.0) < 0.05 and abs(position[2] - 2.0) < 0.05


def test_run_yields_frames_and_write_glb_writes_an_avatar(tmp_path):
    frames = list(bmlr.run([WELCOME], fps=30))
    assert frames[0].time == 0 and abs(frames[1].time - 1 / 30) < 1e-12
    assert any(m.get("id") == "greet:end" for f in frames for m in f.feedback)
    assert frames[-1].poses[""].shape == (57, 4)
    r = bmlr.Realizer(record=True)
    realize(r, WELCOME.read_text(), fps=30)
    out = tmp_path / "greet.glb"
    r.write_glb(out)
    data = out.read_bytes()
    assert data[:4] == b"glTF" and len(data) > 1_000_000
    with pytest.raises(RuntimeError, match="record=True"):
        bmlr.Realizer().write_glb(out)


def test_write_glb_puts_a_walker_s_avatar_where_it_stood(tmp_path):
    # a walk of 2.5 m from the world's place: the avatar starts there (its travel is scaled by
    # leg length from where it stood, not from where the walk ended: that put it 14 cm off)
    world = {"characters": {"Alice": {"position": [1.0, 0.0, 2.0]}}}
    r = bmlr.Realizer(world=world, record=True)
    r.perform(
        '<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a" characterId="Alice">'
        '<locomotion id="w" target="3.5,2"/></bml>'
    )
    for k in range(8 * 30):
        r.tick(k / 30)
    out = tmp_path / "walk.glb"
    r.write_glb(out, "Alice")
    data = out.read_bytes()
    length = int.from_bytes(data[12:16], "little")
    doc = json.loads(data[20 : 20 + length])
    binary = data[20 + length + 8 :]
    animation = doc["animations"][0]
    channel = next(c for c in animation["channels"] if c["target"]["path"] == "translation")
    accessor = doc["accessors"][animation["samplers"][channel["sampler"]]["output"]]
    view = doc["bufferViews"][accessor["bufferView"]]
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    keys = np.frombuffer(binary, np.float32, 3 * accessor["count"], start).reshape(-1, 3)
    assert np.hypot(keys[0][0] - 1.0, keys[0][2] - 2.0) < 0.05, keys[0]
    assert keys[-1][0] - keys[0][0] > 2.0, (keys[0], keys[-1])


def test_step_advances_a_frame_at_fps():
    r = bmlr.Realizer(fps=30)
    r.perform(WELCOME.read_text())
    times = [r.step()[0] for _ in range(4)]
    assert times == [0.0, 1 / 30, 2 / 30, 3 / 30]
    with pytest.raises(ValueError, match="fps"):
        bmlr.Realizer(fps=0)
