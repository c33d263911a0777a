#!/usr/bin/env python3
"""The C host example against `bmlr run`: the same feedback lines, and the same poses.

usage: check_c_host.py RUN.jsonl HOST.jsonl FRAMES.jsonl POSES.txt
RUN.jsonl: `bmlr run --format jsonl` of a block; HOST.jsonl: the host's stdout for it;
FRAMES.jsonl: `bmlr run --frames` of it; POSES.txt: the host's poses (time, x y z w per joint).
Every block and sync-point message (id and times) must be equal, and the poses at every frame
time the two share equal to 1e-6 (the frames file keeps 6 decimals).
"""
import json
import sys


def progress(path):
    out = []
    for line in open(path):
        m = json.loads(line)
        if m["feedback"] in ("blockProgress", "syncPointProgress"):
            out.append((m["feedback"], m["id"], m.get("time"), m.get("globalTime")))
    return out


run_file, host_file, frames_file, poses_file = sys.argv[1:5]
run, host = progress(run_file), progress(host_file)
if run != host or not run:
    sys.exit(f"feedback differs:\n  run:  {run}\n  host: {host}")
lines = open(frames_file).read().splitlines()
names = [j["name"] for j in json.loads(lines[0])["skeleton"]["joints"]]
frames = {}
for line in lines[1:]:
    f = json.loads(line)
    frames[round(f["time"], 6)] = f["characters"][""]["joints"]
compared, worst = 0, 0.0
for line in open(poses_file):
    t, *q = line.split()
    joints = frames.get(round(float(t), 6))
    if joints is None:
        continue
    for k, name in enumerate(names):
        for c in range(4):
            worst = max(worst, abs(float(q[4 * k + c]) - joints[name][c]))
    compared += 1
if compared < len(frames) - 1 or worst > 1e-6:
    sys.exit(f"poses: {compared} of {len(frames)} frames compared, worst difference {worst}")
print(f"{len(run)} progress messages equal; {compared} frames of {len(names)} joints equal "
      f"(worst difference {worst:.1e})")
