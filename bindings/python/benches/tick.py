"""What Python adds to a tick, side by side in one run: one character speaking with a beat, a
wave, a nod and a gaze, ticked at 60 Hz, by `Realizer.tick` called from Python (feedback
turned into dicts, the GIL released) and by the same realizer ticking in Rust
(`_rust_ticks`, no return to Python between ticks), in alternating chunks of 500 ticks.
The target: under 1.2 x.

    python bindings/python/benches/tick.py
"""

import time

import bmlr

BLOCK = """<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
    <gesture id="beat" lexeme="BEAT" mode="RIGHT_HAND" start="0" end="100000"/>
    <gesture id="wave" lexeme="WAVE" mode="LEFT_HAND" start="0" end="100000"/>
    <head id="nod" lexeme="NOD" start="0" end="100000"/>
    <gaze id="look" target="user" start="0" end="100000"/>
    <speech id="s"><text>WORDS</text></speech></bml>"""

CHUNK = 500
ROUNDS = 60
DT = 1 / 60


def main() -> None:
    r = bmlr.Realizer()
    r.perform(BLOCK.replace("WORDS", "la " * 100_000))
    r.tick(1.0)
    t = 1.0
    # alternating chunks, so that both walk through the same stretches of the performance
    ratios, rust_total, python_total = [], 0.0, 0.0
    for _ in range(ROUNDS):
        rust = r._rust_ticks(t, CHUNK, DT)
        t += CHUNK * DT
        clock = time.perf_counter()
        for k in range(CHUNK):
            r.tick(t + k * DT)
        python = time.perf_counter() - clock
        t += CHUNK * DT
        ratios.append(python / rust)
        rust_total += rust
        python_total += python
    ratios.sort()
    n = ROUNDS * CHUNK
    print(f"Rust tick   {rust_total / n * 1e6:.2f} us (mean of {n})")
    print(f"Python tick {python_total / n * 1e6:.2f} us (mean of {n})")
    print(f"ratio       {python_total / rust_total:.3f} (per-chunk median {ratios[ROUNDS // 2]:.3f})")


if __name__ == "__main__":
    main()
