"""A small dialogue loop driving a character: each user line gets a spoken answer with a
gesture; the next turn waits for the answer's block to end (its blockProgress :end feedback).
The whole conversation is written as an animated avatar (dialogue.glb), for Blender or three.js.

    pip install ./bindings/python && python bindings/python/examples/dialogue.py
"""

import sys
from typing import List, Tuple

import bmlr

NS = 'xmlns="http://www.bml-initiative.org/bml/bml-1.0"'

ANSWERS = {
    "hello": ("Hello! Nice to meet you.", "WAVE"),
    "how are you": ("I am fine, thank you for asking.", "BEAT"),
    "bye": ("Goodbye, and have a nice day.", "WAVE"),
}


def answer(turn: int, line: str) -> Tuple[str, str]:
    text, lexeme = ANSWERS.get(line.lower().strip("?!. "), ("Could you say that again?", "BEAT"))
    block = (
        f'<bml {NS} id="turn{turn}" composition="APPEND">'
        f'<speech id="s"><text>{text}</text></speech>'
        f'<gesture id="g" lexeme="{lexeme}" mode="RIGHT_HAND" start="s:start" end="s:end"/>'
        "</bml>"
    )
    return text, block


def main(lines: List[str], fps: float = 60.0, out: str = "dialogue.glb") -> None:
    realizer = bmlr.Realizer(record=True)
    t = 0.0
    for turn, line in enumerate(lines):
        print(f"user:  {line}")
        text, block = answer(turn, line)
        realizer.perform(block)
        done = False
        while not done:
            for message in realizer.tick(t):
                done |= message.get("id") == f"turn{turn}:end"
            t += 1 / fps
        print(f"agent: {text}  (done at {t:.2f} s)")
    realizer.write_glb(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main(sys.argv[1:] or ["Hello", "How are you?", "Bye"])
