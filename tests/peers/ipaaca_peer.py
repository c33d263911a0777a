"""An ipaaca planner written with ipaacar-python (the ipaaca library itself), talking to
`bmlr serve --mqtt URL --ipaaca default,Alice`: the peer that tests/ipaaca.rs runs as a
separate process (ipaacar is GPL-3: it is installed in a venv for the test, never vendored).

Usage: python ipaaca_peer.py HOST:PORT
Prints one line per check ("ok ..." or "FAILED ...") and exits 1 if any failed."""

import asyncio
import json
import sys
import time

from ipaacar.components import InputBuffer, OutputBuffer

NS = 'xmlns="http://www.bml-initiative.org/bml/bml-1.0"'
ADDRESS = sys.argv[1]
failures = []


def check(ok, what):
    print(("ok     " if ok else "FAILED ") + what, flush=True)
    if not ok:
        failures.append(what)


def block(bml_id, character=None):
    who = f' characterId="{character}"' if character else ""
    return f'<bml {NS} id="{bml_id}"{who}><head id="h" lexeme="NOD" start="0" end="0.4"/></bml>'


class Channel:
    """A planner on one channel: sends `bml` messages, hears `bmlfeedback` messages."""

    def __init__(self, name):
        self.name = name
        self.heard = []

    async def start(self):
        self.out = await OutputBuffer.new_with_connect(f"planner-out-{self.name}", self.name, ADDRESS)
        self.inp = await InputBuffer.new_with_connect(f"planner-in-{self.name}", self.name, ADDRESS)

        async def on_feedback(msg, **kw):
            self.heard.append(json.loads(msg)["bmlfeedback"])

        async def on_notify(msg, **kw):
            self.heard.append("notify:" + msg)

        await self.inp.listen_for_messages("bmlfeedback", on_feedback)
        await self.inp.listen_for_messages("componentNotify", on_notify)

    async def until(self, test, secs=10.0):
        end = time.time() + secs
        while time.time() < end:
            if test():
                return True
            await asyncio.sleep(0.05)
        return test()

    def has(self, *parts):
        return any(all(p in fb for p in parts) for fb in self.heard)


async def main():
    default, alice = Channel("default"), Channel("Alice")
    await default.start()
    await alice.start()
    await asyncio.sleep(0.5)

    # 1. a component announcing itself is answered
    note = {"name": "planner", "function": "planner", "send_categories": "bml",
            "receive_categories": "bmlfeedback", "state": "new"}
    await alice.out.send_message("componentNotify", json.dumps(note))
    answered = await alice.until(lambda: any('"state":"old"' in h and '"bmlrealizer"' in h
                                              for h in alice.heard), 5)
    check(answered, "the realizer answers a componentNotify 'new' with its own ('old', bmlrealizer)")

    # 2. each channel's block: its start and end there, nothing of the other's
    await default.out.send_message("bml", json.dumps({"bml": block("d1")}))
    await alice.out.send_message("bml", json.dumps({"bml": block("a1")}))
    for ch, mine, other in ((default, "d1", "a1"), (alice, "a1", "d1")):
        ended = await ch.until(lambda: ch.has("blockProgress", f'id="{mine}:end"'))
        check(ch.has("blockProgress", f'id="{mine}:start"') and ended,
              f"{ch.name}: its block's start and end arrive as bmlfeedback messages within 10 s")
        check(not any(f'"{other}' in fb or f'id="{other}:' in fb for fb in ch.heard),
              f"{ch.name}: nothing of the other channel's block")
    check(alice.has('characterId="Alice"'), "Alice's feedback names the character Alice")

    # 3. garbage: a warning on that channel, then the next block runs
    await alice.out.send_message("bml", "this is not BML")
    warned = await alice.until(lambda: alice.has("warningFeedback"), 5)
    check(warned, "a garbage payload gives a warningFeedback on its channel")
    await alice.out.send_message("bml", json.dumps({"bml": block("a2")}))
    check(await alice.until(lambda: alice.has(f'id="a2:end"')), "the next block runs after the garbage")

    # 4. AsapRealizer's request IU: answered by updates of the IU itself
    statuses = []
    iu = await alice.out.create_new_iu(
        "realizerRequest", json.dumps({"type": "bml", "request": block("r1", "Alice")}))

    async def on_update(iu, event, **kw):
        statuses.append(json.loads(await iu.get_payload()))

    await iu.add_callback(on_update)
    done = await alice.until(lambda: any(s.get("status") == "DONE" for s in statuses))
    seen = [s.get("status") for s in statuses]
    # (a callback reads the payload as it is then: ((RECEIVED)) is followed at once by
    # IN_EXEC when the block starts at once, so the first status seen may be either)
    order = {"((RECEIVED))": 0, "IN_EXEC": 1, "DONE": 2}
    ranks = [order.get(s, -1) for s in seen]
    check(done and "IN_EXEC" in seen and ranks == sorted(ranks) and min(ranks) >= 0,
          f"a realizerRequest IU is updated in order to IN_EXEC, then DONE (saw {sorted(set(seen))})")
    last = json.loads(await iu.get_payload())
    check(last.get("bmlid") == "r1" and last.get("type") == "bml" and "predictedEndTime" in last,
          f"the IU keeps its keys and gains bmlid, predictedEndTime (payload keys {sorted(last)})")
    bad = await alice.out.create_new_iu("realizerRequest", json.dumps({"type": "bml", "request": "<bml"}))
    bad_status = []

    async def on_bad(iu, event, **kw):
        bad_status.append(json.loads(await iu.get_payload()))

    await bad.add_callback(on_bad)
    errored = await alice.until(lambda: any(s.get("status") == "ERROR" and s.get("error")
                                            for s in bad_status), 5)
    check(errored, "a request IU with a block that cannot be read gets status ERROR with the error")

    print(f"{len(failures)} failed", flush=True)
    return 1 if failures else 0


sys.exit(asyncio.run(main()))
