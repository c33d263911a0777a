#!/usr/bin/env python3
"""Loads the BVH files `bmlr run --bvh` writes for the documented examples in an independent BVH
parser (the PyPI package `bvh`) and checks joints, channels and frame counts."""
import json
import subprocess
import sys
import tempfile

from bvh import Bvh

BMLR = sys.argv[1]
RUNS = [
    ["fixtures/examples/welcome.xml"],
    ["fixtures/examples/gaze-then-point.xml"],
    ["fixtures/examples/long-speech.xml", "+1.5", "fixtures/examples/interrupt-speech.xml"],
    ["fixtures/examples/reply.xml", "+2", "fixtures/examples/listen.xml"],
    ["fixtures/examples/lift-and-wave.xml"],
]
FPS = 30
skeleton = json.load(open("fixtures/skeletons/adult.json"))
joints = [j["name"] for j in skeleton["joints"]]
failed = False
for items in RUNS:
    with tempfile.NamedTemporaryFile(suffix=".bvh") as f:
        log = subprocess.run(
            [BMLR, "run", "--format", "jsonl", "--fps", str(FPS), "--bvh", f.name, *items],
            check=True, capture_output=True, text=True,
        ).stdout
        last = max(json.loads(l)["globalTime"] for l in log.splitlines() if '"globalTime"' in l)
        b = Bvh(open(f.name).read())
        expected_frames = int(last * FPS + 1e-9) + 1  # frames on the 1/FPS grid up to the last event
        problems = []
        if sorted(b.get_joints_names()) != sorted(joints):
            problems.append(f"joints {b.get_joints_names()}")
        if b.joint_channels("HumanoidRoot") != ["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"]:
            problems.append("root channels")
        if any(b.joint_channels(j) != ["Zrotation", "Xrotation", "Yrotation"] for j in joints[1:]):
            problems.append("joint channels")
        if b.nframes != expected_frames or abs(b.frame_time - 1 / FPS) > 1e-6:
            problems.append(f"{b.nframes} frames of {b.frame_time} s, expected {expected_frames} of {1 / FPS}")
        print(f"{' '.join(items)}: {len(b.get_joints_names())} joints, {b.nframes} frames"
              + (f" -- FAILED: {'; '.join(problems)}" if problems else ""))
        failed |= bool(problems)
sys.exit(1 if failed else 0)
