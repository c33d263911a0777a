#!/usr/bin/env python3
"""Draws the plaza from above (docs/plaza-paths.png): the walkers' paths from a frames file,
the obstacles and the conversing group of the world file, a cross where each walker ended.
Needs matplotlib.

    bmlr run --world fixtures/examples/plaza/world.json fixtures/examples/plaza \\
        --frames plaza.jsonl > /dev/null
    python3 tools/plaza_paths.py plaza.jsonl fixtures/examples/plaza/world.json docs/plaza-paths.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(frames_path, world_path, out):
    lines = open(frames_path).read().splitlines()
    frames = [json.loads(line) for line in lines[1::6]]
    world = json.load(open(world_path))
    fig, ax = plt.subplots(figsize=(7, 7))
    for o in world.get("obstacles", []):
        if "circle" in o:
            x, z, r = o["circle"]
            ax.add_patch(plt.Circle((x, z), r, color="0.6"))
        if "box" in o:
            x0, z0, x1, z1 = o["box"]
            ax.add_patch(plt.Rectangle((x0, z0), x1 - x0, z1 - z0, color="0.6"))
    members = {m for g in world.get("groups", []) for m in g["members"]}
    for cid, c in world["characters"].items():
        if cid in members:
            ax.add_patch(plt.Circle((c["position"][0], c["position"][2]), 0.25, color="crimson"))
    for cid in frames[0]["characters"]:
        xs = [f["characters"][cid]["root"][0] for f in frames]
        zs = [f["characters"][cid]["root"][2] for f in frames]
        ax.plot(xs, zs, "-", lw=0.8)
        ax.plot(xs[-1], zs[-1], "x", ms=4, color="k")
    ax.set_aspect("equal")
    ax.set_xlim(-12.5, 12.5)
    ax.set_ylim(-12.5, 12.5)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_title("40 walkers crossing a plaza round a fountain, benches and three conversing")
    fig.tight_layout()
    fig.savefig(out, dpi=80)


if __name__ == "__main__":
    main(*sys.argv[1:4])
