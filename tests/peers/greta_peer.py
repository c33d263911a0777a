"""A Greta-side peer written with stomp.py (PyPI), talking to `bmlr serve --stomp URL --flavour
greta` on an ActiveMQ: the peer that tests/activemq.rs runs as a separate process.

It speaks as Greta's ActiveMQ components do: a BML block goes to the topic `greta.BML` as a text
message (no content-length, so ActiveMQ makes a JMS TextMessage of it) with the properties
Greta's BML sender sets (content-type, datatype, source, event, xml, content-id); the block's
callbacks come back on `greta.output.feedback.BML` as Greta's BML callbacks sender makes them: an
empty body whose properties `feedback-type` (start, end, stopped, dead), `feedback-id` (the
block) and `feedback-time` (ms) say what happened.

Usage: python greta_peer.py HOST:PORT
Prints one line per check ("ok ..." or "FAILED ...") and exits 1 if any failed."""

import sys
import threading
import time

import stomp

NS = 'xmlns="http://www.bml-initiative.org/bml/bml-1.0"'
HOST, PORT = sys.argv[1].rsplit(":", 1)
failures = []


def check(ok, what):
    print(("ok     " if ok else "FAILED ") + what, flush=True)
    if not ok:
        failures.append(what)


class Heard(stomp.ConnectionListener):
    def __init__(self):
        self.frames = []
        self.lock = threading.Lock()

    def on_message(self, frame):
        with self.lock:
            self.frames.append((dict(frame.headers), frame.body))

    def wait_for(self, pred, secs):
        until = time.time() + secs
        while time.time() < until:
            with self.lock:
                found = [f for f in self.frames if pred(f)]
            if found:
                return found[0]
            time.sleep(0.02)
        return None


def callback(kind, block):
    return lambda f: f[0].get("feedback-type") == kind and f[0].get("feedback-id") == block


conn = stomp.Connection12([(HOST, int(PORT))], auto_content_length=False)
heard = Heard()
conn.set_listener("", heard)
conn.connect(wait=True)
conn.subscribe("/topic/greta.output.feedback.BML", id="1", ack="auto")
time.sleep(0.3)

GRETA_PROPERTIES = {
    "content-type": "utterance",
    "datatype": "BML",
    "source": "Greta",
    "event": "single",
    "xml": "true",
}


def send_block(body, content_id):
    conn.send("/topic/greta.BML", body, headers=dict(GRETA_PROPERTIES, **{"content-id": content_id}))


send_block(f'<bml {NS} id="greet"><head id="h" lexeme="NOD" start="0" end="0.4"/></bml>', "greet")
start = heard.wait_for(callback("start", "greet"), 10)
end = heard.wait_for(callback("end", "greet"), 10)
check(start is not None, "the block's start as a callback (feedback-type start, feedback-id greet)")
check(end is not None, "the block's end as a callback (feedback-type end) within 10 s")
if start and end:
    check(start[1] == "" and end[1] == "", "callbacks have an empty body, as Greta's sender makes them")
    t0, t1 = start[0].get("feedback-time", ""), end[0].get("feedback-time", "")
    check(t0.isdigit() and t1.isdigit(), f"feedback-time is whole milliseconds ({t0!r}, {t1!r})")
    if t0.isdigit() and t1.isdigit():
        check(350 <= int(t1) - int(t0) <= 600, f"end - start is the block's 0.4 s ({int(t1) - int(t0)} ms)")
check(
    all(f[0].get("feedback-type") in ("start", "end", "stopped", "dead", "warning") for f in heard.frames),
    "every message is one of Greta's callback types (or a warning)",
)

# garbage: a warning, then the next block runs
send_block("this is not BML <", "junk")
warn = heard.wait_for(lambda f: f[0].get("feedback-type") == "warning", 10)
check(warn is not None and "warningFeedback" in warn[1], "garbage gives a warning (its XML in the body)")
send_block(f'<bml {NS} id="after"><head id="h" lexeme="NOD" start="0" end="0.2"/></bml>', "after")
check(heard.wait_for(callback("end", "after"), 10) is not None, "the next block runs to its end")

# interrupted: Greta's "stopped"
send_block(f'<bml {NS} id="long"><head id="h" lexeme="NOD" start="0" end="5"/></bml>', "long")
heard.wait_for(callback("start", "long"), 10)
send_block(
    f'<bml {NS} id="stop" composition="REPLACE"><head id="h" lexeme="NOD" start="0" end="0.2"/></bml>', "stop"
)
check(heard.wait_for(callback("stopped", "long"), 10) is not None, "a block cut short by REPLACE is 'stopped'")

conn.disconnect()
print(f"{len(failures)} failed", flush=True)
sys.exit(1 if failures else 0)
