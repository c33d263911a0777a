"""Streaming a speech's sound from Python (`open_stream`, `push_audio`, `end_audio`), as a host
with a cloud voice does: espeak-ng's sentence (fixtures/voice/espeak-bob.wav) pushed in 10
chunks, each with the Polly word marks written from espeak-ng's own word reports, moves the face
as the whole file with the whole marks does (within one frame), ends with its sound with honest
feedback, and an interrupt mid-stream stops sound and lips in the next frame."""

import json
import wave
from pathlib import Path

import numpy as np
import pytest

import bmlr

ROOT = Path(__file__).resolve().parents[3]
VOICE = ROOT / "fixtures" / "voice"
NS = (
    'xmlns="http://www.bml-initiative.org/bml/bml-1.0" '
    'xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" xmlns:bmla="http://www.asap-project.org/bmla"'
)
FPS = 60.0
STREAMED = (
    f'<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" '
    'end="anticipators:reply:end"><text>{text}</text></speech>{more}</bml>'
)


def sound():
    with wave.open(str(VOICE / "espeak-bob.wav")) as w:
        assert w.getnchannels() == 1 and w.getsampwidth() == 2
        return w.getframerate(), np.frombuffer(w.readframes(w.getnframes()), dtype="<i2")


def word_marks():
    """The text and its Polly word marks, (seconds, JSON line) each, from espeak-ng's report."""
    report = json.loads((VOICE / "espeak-bob.events.json").read_text())
    text = report["text"]
    marks = []
    for e in report["events"]:
        if e["type"] == "word" and e["length"] > 0:
            a, b = e["start"], e["start"] + e["length"]
            line = {"time": e["ms"], "type": "word", "start": a, "end": b, "value": text[a:b]}
            marks.append((e["ms"] / 1000, json.dumps(line)))
    return text, marks


def sync_time(feedback, sync_id):
    return next(
        (m["globalTime"] for m in feedback
         if m["feedback"] == "syncPointProgress" and m["id"] == sync_id),
        None,
    )


def face(r):
    return np.array(list(r.morphs().values()), dtype=np.float32)


def test_a_streamed_speech_moves_as_its_whole_file(tmp_path):
    rate, pcm = sound()
    length = len(pcm) / rate
    text, marks = word_marks()
    whole_marks = tmp_path / "whole.marks"
    whole_marks.write_text("\n".join(line for _, line in marks))
    whole = bmlr.Realizer(idle=False)
    whole.perform(
        f'<bml {NS} id="w"><speech id="s" bmlt:audiofile="{VOICE / "espeak-bob.wav"}" '
        f'bmlt:marks="{whole_marks}"><text>{text}</text></speech></bml>'
    )
    reference = []
    for k in range(int(length * FPS) + 1):
        whole.tick(k / FPS)
        reference.append(face(whole))

    r = bmlr.Realizer(idle=False)
    r.open_stream("reply")
    r.perform(STREAMED.format(text=text, more='<head id="n" lexeme="NOD" start="s:end"/>'))
    chunk = -(-len(pcm) // 10)
    pushed, feedback, streamed = 0, [], []
    for k in range(int((length + 2.5) * FPS)):
        t = k / FPS
        while pushed < 10 and t >= 0.5 + 0.2 * pushed:
            a, b = pushed * chunk, min((pushed + 1) * chunk, len(pcm))
            these = [line for at, line in marks
                     if at >= a / rate and (at < b / rate or pushed == 9)]
            r.push_audio("reply", pcm[a:b], rate, "\n".join(these))
            pushed += 1
            if pushed == 10:
                r.end_audio("reply")
        feedback += r.tick(t)
        streamed.append((t, face(r)))
    start = sync_time(feedback, "b:s:start")
    assert start is not None and abs(start - 0.5) < 1e-3, start
    differ, moving = 0, 0
    for t, w in streamed:
        if not start <= t < start + length - 1 / FPS:
            continue
        k = round((t - start) * FPS)
        near = [reference[i] for i in (k - 1, k, k + 1) if 0 <= i < len(reference)]
        moving += int(w.max() > 0.2)
        differ += int(not any(np.abs(x - w).max() < 0.05 for x in near))
    assert moving > 50, f"the face moves in {moving} frames"
    assert differ == 0, f"{differ} frames whose face differs from the whole file's"
    end = sync_time(feedback, "b:s:end")
    assert end is not None and abs(end - (start + length)) <= 1.5 / FPS, (end, start + length)
    predicted = [m for m in feedback if m["feedback"] == "predictionFeedback"]
    assert len(predicted) >= 9, predicted
    assert sync_time(feedback, "b:n:start") == end, "the nod on the speech's end follows it"


def test_an_interrupt_mid_stream_stops_sound_and_lips_in_one_frame():
    rate, pcm = sound()
    text, _ = word_marks()
    r = bmlr.Realizer(idle=False)
    r.open_stream("reply")
    r.perform(STREAMED.format(text=text, more=""))
    r.push_audio("reply", pcm[: len(pcm) // 2], rate)
    talking = 0
    for k in range(60):
        r.tick(k / FPS)
        talking += int(r.morphs()["jawOpen"] > 0.1 and len(r.sounds()) == 1)
    assert talking > 10, f"it speaks ({talking} frames)"
    assert r.sounds()[0][0] == "b:s"
    r.perform(f'<bml {NS} id="i"><bmla:interrupt id="x" target="b" start="0"/></bml>')
    feedback = r.tick(61 / FPS)
    assert r.sounds() == [], "the sound stops at once"
    assert face(r).max() < 0.05, "the face is at rest at once"
    end = sync_time(feedback, "b:s:end")
    assert end is not None and end <= 61 / FPS + 1e-3, end


def test_wrong_stream_calls_raise_readable_errors():
    r = bmlr.Realizer(idle=False)
    with pytest.raises(KeyError, match="no stream 'reply' is open"):
        r.push_audio("reply", np.zeros(10, dtype=np.int16), 16000)
    with pytest.raises(ValueError, match="empty"):
        r.open_stream("")
    r.open_stream("reply")
    r.push_audio("reply", np.zeros(10, dtype=np.int16), 16000)
    with pytest.raises(ValueError, match="22050 Hz after chunks at 16000 Hz"):
        r.push_audio("reply", np.zeros(10, dtype=np.int16), 22050)
    with pytest.raises(ValueError, match="line 1"):
        r.push_audio("reply", np.zeros(10, dtype=np.int16), 16000, '{"time":')
    with pytest.raises(TypeError):
        r.push_audio("reply", np.zeros(10, dtype=np.float32), 16000)
    r.end_audio("reply")
    with pytest.raises(ValueError, match="has ended"):
        r.push_audio("reply", np.zeros(10, dtype=np.int16), 16000)
    with pytest.raises(KeyError):
        r.end_audio("other")
