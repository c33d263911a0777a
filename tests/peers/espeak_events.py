"""Say a text with espeak-ng's own library and write what it reports: the sound as a WAV and
its events (words and phonemes, with their times) as JSON. A test helper, run as a separate
process (espeak-ng is GPL-3; the realizer never links it).

usage: espeak_events.py VOICE TEXT OUT.wav OUT.json
"""
import ctypes
import json
import sys
import wave

AUDIO_OUTPUT_SYNCHRONOUS = 2
INITIALIZE_PHONEME_EVENTS = 0x0001
INITIALIZE_PHONEME_IPA = 0x0002
POS_CHARACTER = 1
CHARS_UTF8 = 1
EVENT_WORD, EVENT_SENTENCE, EVENT_MARK, EVENT_PLAY, EVENT_END, EVENT_MSG_TERMINATED, EVENT_PHONEME = 1, 2, 3, 4, 5, 6, 7


class Id(ctypes.Union):
    _fields_ = [("number", ctypes.c_int), ("name", ctypes.c_char_p), ("string", ctypes.c_char * 8)]


class Event(ctypes.Structure):
    _fields_ = [
        ("type", ctypes.c_int),
        ("unique_identifier", ctypes.c_uint),
        ("text_position", ctypes.c_int),
        ("length", ctypes.c_int),
        ("audio_position", ctypes.c_int),
        ("sample", ctypes.c_int),
        ("user_data", ctypes.c_void_p),
        ("id", Id),
    ]


def main():
    voice, text, wav_path, json_path = sys.argv[1:5]
    lib = ctypes.CDLL("libespeak-ng.so.1")
    rate = lib.espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, None, INITIALIZE_PHONEME_EVENTS | INITIALIZE_PHONEME_IPA)
    if rate <= 0:
        sys.exit("espeak-ng did not start")
    if lib.espeak_SetVoiceByName(voice.encode()) != 0:
        sys.exit(f"espeak-ng has no voice {voice}")
    samples = bytearray()
    events = []
    Callback = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int, ctypes.POINTER(Event))

    def on_synth(wav, count, ev):
        if wav and count > 0:
            samples.extend(ctypes.string_at(wav, count * 2))
        i = 0
        while ev[i].type != 0:
            e = ev[i]
            if e.type == EVENT_WORD:
                events.append({"type": "word", "ms": e.audio_position, "start": e.text_position - 1, "length": e.length})
            elif e.type == EVENT_PHONEME:
                events.append({"type": "phoneme", "ms": e.audio_position, "ipa": e.id.string.decode("utf-8", "replace")})
            elif e.type == EVENT_SENTENCE:
                events.append({"type": "sentence", "ms": e.audio_position})
            elif e.type == EVENT_END:
                events.append({"type": "end", "ms": e.audio_position})
            i += 1
        return 0

    callback = Callback(on_synth)
    lib.espeak_SetSynthCallback(callback)
    data = text.encode("utf-8")
    lib.espeak_Synth(data, len(data) + 1, 0, POS_CHARACTER, 0, CHARS_UTF8, None, None)
    lib.espeak_Synchronize()
    with wave.open(wav_path, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(rate)
        w.writeframes(bytes(samples))
    with open(json_path, "w") as f:
        json.dump({"voice": voice, "text": text, "rate": rate, "samples": len(samples) // 2, "events": events}, f, indent=1)


main()
