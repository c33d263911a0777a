"""bmlr: a BML realizer for virtual humans.

Give it BML blocks, tick it with your clock, and read back the BML 1.0 feedback (as the dicts
of ``bmlr run --format jsonl``) and each character's body: its pose (joints x quaternion, as a
numpy array), root and ARKit blendshape weights. ``run`` realizes files frame by frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, Iterable, Iterator, List, Union

import numpy as np

from ._bmlr import BmlError, Realizer, validate

__all__ = ["BmlError", "Frame", "Realizer", "run", "validate"]


@dataclass
class Frame:
    """One frame of a run: its time, the feedback sent since the previous frame, and each
    character's pose (joints x 4, x y z w) by id ("" is the default character)."""

    time: float
    feedback: List[Dict[str, Any]]
    poses: Dict[str, "np.ndarray"]


def run(
    files: Iterable[Union[str, Path]], fps: float = 60.0, **options: Any
) -> Iterator[Frame]:
    """Realizes the BML files (all sent at time 0) and yields a frame every 1/fps seconds until
    nothing more is scheduled. ``options`` go to ``Realizer`` (world, tts, idle, character)."""
    if not fps > 0:
        raise ValueError(f"fps must be above 0, not {fps}")
    realizer = Realizer(**options)
    for f in files:
        realizer.perform(Path(f).read_text(encoding="utf-8"))
    k = 0
    while True:
        t = k / fps
        feedback = realizer.tick(t)
        poses = {c: realizer.pose(c) for c in realizer.characters()}
        yield Frame(t, feedback, poses)
        if realizer.next_event() is None:
            return
        k += 1
