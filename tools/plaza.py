#!/usr/bin/env python3
"""Writes fixtures/examples/plaza/: a plaza 24 m square with a fountain and two benches, three
people conversing near the middle, and 40 walkers crossing it between its edges (one BML block
each). Deterministic: the same files every run.

    python3 tools/plaza.py
"""
import json
import math
import os
import random

OUT = os.path.join(os.path.dirname(__file__), "..", "fixtures", "examples", "plaza")
NS = "http://www.bml-initiative.org/bml/bml-1.0"


def main():
    rng = random.Random(7)
    os.makedirs(OUT, exist_ok=True)
    for f in os.listdir(OUT):
        if f.endswith(".xml"):
            os.remove(os.path.join(OUT, f))
    characters = {}
    # three conversing at (3, 2), facing the middle of their ring
    for k in range(3):
        a = math.radians(20 + 120 * k)
        x, z = 3 + 0.9 * math.sin(a), 2 + 0.9 * math.cos(a)
        facing = math.degrees(math.atan2(3 - x, 2 - z))
        characters[f"talker{k}"] = {"position": [round(x, 3), 0, round(z, 3)], "facing": round(facing, 1)}
    # walkers from one edge to another (never the same edge), starts and goals 1 m apart
    spots = [(-11.0 + 1.0 * i, side) for i in range(23) for side in range(4)]
    def place(t, side):
        return {0: (t, -11.5), 1: (t, 11.5), 2: (-11.5, t), 3: (11.5, t)}[side]
    rng.shuffle(spots)
    starts = spots[:40]
    used = set(starts)
    free = [s for s in spots if s not in used]
    for k, (t, side) in enumerate(starts):
        goal = next(g for g in free if g[1] != side and abs(g[0] - t) > 2)
        free.remove(goal)
        sx, sz = place(t, side)
        gx, gz = place(*goal)
        facing = math.degrees(math.atan2(gx - sx, gz - sz))
        cid = f"walker{k:02d}"
        characters[cid] = {"position": [sx, 0, sz], "facing": round(facing, 1)}
        with open(os.path.join(OUT, f"{cid}.xml"), "w") as f:
            f.write(f'<bml xmlns="{NS}" id="cross{k:02d}" characterId="{cid}">\n'
                    f'  <locomotion id="walk" target="{gx},{gz}"/>\n</bml>\n')
    world = {
        "obstacles": [
            {"circle": [-3, -2, 1.5], "height": 0.8},
            {"box": [-8, 5, -6.2, 5.5], "height": 0.45},
            {"box": [6, -7, 6.5, -5.2], "height": 0.45},
        ],
        "characters": characters,
        "groups": [{"members": ["talker0", "talker1", "talker2"], "conversing": True}],
    }
    with open(os.path.join(OUT, "world.json"), "w") as f:
        json.dump(world, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
