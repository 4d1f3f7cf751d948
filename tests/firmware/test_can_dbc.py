#!/usr/bin/env python3
"""test_can_dbc.py --dump BIN --dbc FILE --pydeps DIR: the C CAN codec (fw_can.h) and the
DBC file (can/dhcal.dbc) describe the same protocol.

cantools (an independent DBC implementation) decodes every frame the C encoder makes to the
same physical values the C side put in (codes to volts by the DBC's scale and offset), and
the C decoder reads every frame cantools encodes from physical values back to the same raw
values; at the boundaries of every signal and on random values. The bits the DBC leaves to
no signal are exactly the ones the C codec keeps zero and rejects when set; wrong lengths,
out-of-range fields and foreign ids are rejected by the C side.

cantools is imported from the environment, else installed with pip into DIR (PyPI). Without
it the test cannot mean anything: it exits 77 (CTest SKIP_RETURN_CODE) with the reason."""
import argparse
import importlib
import os
import random
import subprocess
import sys

SKIP = 77
DAC_V_PER_CODE = 10.0 / 2048.0  # the drive's converters: +-10 V over 12 bits, offset binary


def load_cantools(pydeps):
    try:
        return importlib.import_module("cantools")
    except ImportError:
        pass
    os.makedirs(pydeps, exist_ok=True)
    if pydeps not in sys.path:
        sys.path.insert(0, pydeps)
    try:
        return importlib.import_module("cantools")
    except ImportError:
        pass
    cmd = [sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
           "--timeout", "30", "--retries", "2", "--target", pydeps, "cantools>=39,<46"]
    print("installing cantools:", " ".join(cmd), flush=True)
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, timeout=600, check=False)
    except (OSError, subprocess.TimeoutExpired) as e:
        print(f"SKIP: cannot run pip to install cantools: {e}")
        sys.exit(SKIP)
    if run.returncode != 0:
        print(f"SKIP: pip could not install cantools (exit {run.returncode}):\n"
              f"{run.stdout}{run.stderr}")
        sys.exit(SKIP)
    importlib.invalidate_caches()
    try:
        return importlib.import_module("cantools")
    except ImportError as e:
        print(f"SKIP: cantools installed into {pydeps} but does not import: {e}")
        sys.exit(SKIP)


class Codec:
    """The C codec through can_codec_dump, all requests of a batch in one process."""

    def __init__(self, exe):
        self.exe = exe

    def run(self, requests):
        out = subprocess.run([self.exe], input="\n".join(requests) + "\n", capture_output=True,
                             text=True, timeout=60, check=True).stdout.splitlines()
        assert len(out) == len(requests), (len(out), len(requests))
        return out

    @staticmethod
    def frame(line):
        w = line.split()
        assert w[0] == "frame", line
        return int(w[1], 16), bytes.fromhex(w[3]) if len(w) > 3 else b""


def volts(code):
    return (code - 2048) * DAC_V_PER_CODE


class Checker:
    def __init__(self):
        self.failures = []
        self.checks = 0

    def eq(self, what, got, want):
        self.checks += 1
        if got != want:
            self.failures.append(f"{what}: got {got!r}, want {want!r}")


def messages_of(db):
    by_name = {m.name: m for m in db.messages}
    return by_name


def raw_cases(rng, n_random):
    """(kind, drive, field tuple) cases: every signal at its boundaries, then random ones."""
    codes = [0, 1, 2047, 2048, 2049, 4094, 4095]
    u16 = [0, 1, 255, 256, 32767, 32768, 65534, 65535]
    cases = []
    for t in u16:
        cases.append(("sync", 0, (t,)))
    for j in range(3):
        for c in codes:
            for en in (0, 1):
                cases.append(("cmd", j, (c, en, u16[(c + en) % len(u16)])))
        for e in u16:
            for c in (0, 2048, 4095):
                for flags in range(8):
                    cases.append(("fb", j, (e, c, flags & 1, (flags >> 1) & 1, (flags >> 2) & 1,
                                            u16[flags])))
    for w in u16:
        cases.append(("wires", 0, (w, 65535 - w, u16[(w * 7) % len(u16)], w)))
    for _ in range(n_random):
        j = rng.randrange(3)
        cases.append(("sync", 0, (rng.randrange(65536),)))
        cases.append(("cmd", j, (rng.randrange(4096), rng.randrange(2), rng.randrange(65536))))
        cases.append(("fb", j, (rng.randrange(65536), rng.randrange(4096), rng.randrange(2),
                                rng.randrange(2), rng.randrange(2), rng.randrange(65536))))
        cases.append(("wires", 0, tuple(rng.randrange(65536) for _ in range(4))))
    return cases


def request(kind, j, f):
    if kind in ("sync", "wires"):
        return "enc %s %s" % (kind, " ".join(map(str, f)))
    return "enc %s %d %s" % (kind, j, " ".join(map(str, f)))


def msg_name(kind, j):
    return {"sync": "SYNC", "cmd": f"DRIVE_CMD_{j}", "fb": f"DRIVE_FB_{j}",
            "wires": "MEAS_WIRES"}[kind]


def physical(kind, f):
    """What cantools must decode from a frame carrying the raw fields f."""
    if kind == "sync":
        return {"Tick": f[0]}
    if kind == "cmd":
        return {"DacVoltage": volts(f[0]), "Enable": f[1], "Tick": f[2]}
    if kind == "fb":
        return {"EncoderCount": f[0], "TachoVoltage": volts(f[1]), "Enabled": f[2],
                "Saturated": f[3], "Fault": f[4], "Tick": f[5]}
    return {"Wire1Count": f[0], "Wire2Count": f[1], "Wire3Count": f[2], "Tick": f[3]}


def signal_mask(msg):
    """Bits of the payload (as a little-endian integer) that the DBC gives to a signal."""
    mask = 0
    for s in msg.signals:
        assert s.byte_order == "little_endian", s.name
        mask |= ((1 << s.length) - 1) << s.start
    return mask


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dump", required=True)
    ap.add_argument("--dbc", required=True)
    ap.add_argument("--pydeps", required=True)
    ap.add_argument("--random", type=int, default=500)
    a = ap.parse_args()
    cantools = load_cantools(a.pydeps)
    db = cantools.database.load_file(a.dbc, strict=True)
    msgs = messages_of(db)
    c = Checker()
    codec = Codec(a.dump)
    rng = random.Random(20261122)

    # The message set: names, ids, lengths, standard frames, 1 ms cycle.
    want = {"SYNC": (0x080, 2), "MEAS_WIRES": (0x200, 8)}
    for j in range(3):
        want[f"DRIVE_CMD_{j}"] = (0x100 + j, 4)
        want[f"DRIVE_FB_{j}"] = (0x180 + j, 6)
    c.eq("DBC messages", sorted(msgs), sorted(want))
    for name, (fid, dlc) in want.items():
        m = msgs[name]
        c.eq(f"{name} id", m.frame_id, fid)
        c.eq(f"{name} length", m.length, dlc)
        c.eq(f"{name} extended", m.is_extended_frame, False)

    # C encodes -> cantools decodes to the physical values put in.
    cases = raw_cases(rng, a.random)
    out = codec.run([request(k, j, f) for k, j, f in cases])
    unused_bits_seen = {}
    for (kind, j, f), line in zip(cases, out):
        name = msg_name(kind, j)
        fid, data = Codec.frame(line)
        m = msgs[name]
        c.eq(f"{name} C id", fid, m.frame_id)
        c.eq(f"{name} C length", len(data), m.length)
        decoded = m.decode(data, decode_choices=False, scaling=True)
        c.eq(f"cantools({name} {f})", {k: decoded[k] for k in decoded}, physical(kind, f))
        payload = int.from_bytes(data, "little")
        unused_bits_seen[name] = unused_bits_seen.get(name, 0) | (payload & ~signal_mask(m))
    for name, bits in unused_bits_seen.items():
        c.eq(f"{name}: bits outside every DBC signal set by the C encoder", bits, 0)

    # cantools encodes physical values -> the C decoder gives the raw fields back.
    reqs = []
    for kind, j, f in cases:
        m = msgs[msg_name(kind, j)]
        data = m.encode(physical(kind, f), scaling=True, strict=True)
        reqs.append(f"dec {m.frame_id:x} {len(data)} {data.hex()}")
    out = codec.run(reqs)
    for (kind, j, f), line in zip(cases, out):
        c.eq(f"C decode of cantools {msg_name(kind, j)}", line, request(kind, j, f))

    # Reserved bits (in the payload, outside every DBC signal): each one set alone is
    # rejected by the C decoder, though cantools would read past it.
    reqs = []
    expect = []
    for name, m in msgs.items():
        free = ~signal_mask(m) & ((1 << (8 * m.length)) - 1)
        for bit in range(8 * m.length):
            if free >> bit & 1:
                data = (1 << bit).to_bytes(m.length, "little")
                reqs.append(f"dec {m.frame_id:x} {m.length} {data.hex()}")
                expect.append(f"{name} reserved bit {bit}")
    n_reserved = len(reqs)
    c.eq("reserved bits in the DBC (cmd 3 each, fb 1 each)", n_reserved, 3 * 3 + 3 * 1)
    for what, line in zip(expect, codec.run(reqs)):
        c.eq(what, line, "err reserved")

    # Exact lengths: one byte less or more is rejected, for every message.
    reqs = []
    expect = []
    for name, m in msgs.items():
        for n in range(0, 9):
            if n != m.length:
                reqs.append(f"dec {m.frame_id:x} {n} {'00' * n}")
                expect.append(f"{name} with length {n}")
    for what, line in zip(expect, codec.run(reqs)):
        c.eq(what, line, "err dlc")

    # Out of range for the signal: rejected by the encoder, and by cantools the same way.
    bad = [("enc cmd 0 4096 1 0", "err range"), ("enc cmd 0 2048 2 0", "err range"),
           ("enc cmd 3 2048 1 0", "err argument"), ("enc fb 1 0 4096 0 0 0 0", "err range"),
           ("enc fb 1 0 0 2 0 0 0", "err range"), ("enc fb 1 0 0 0 2 0 0", "err range"),
           ("enc fb 1 0 0 0 0 2 0", "err range"), ("enc fb 3 0 0 0 0 0 0", "err argument"),
           ("dec 103 4 00080000", "err id"), ("dec 183 6 000000000000", "err id"),
           ("dec 7ff 2 0000", "err id"), ("dec 81 2 0000", "err id")]
    for (req, want_line), line in zip(bad, codec.run([r for r, _ in bad])):
        c.eq(req, line, want_line)
    for name, sig, v in (("DRIVE_CMD_0", "DacVoltage", 10.0), ("DRIVE_CMD_0", "DacVoltage", -10.01),
                         ("DRIVE_FB_0", "TachoVoltage", 10.0)):
        m = msgs[name]
        vals = {s.name: (0 if s.name != sig else v) for s in m.signals}
        try:
            m.encode(vals, scaling=True, strict=True)
            c.failures.append(f"cantools accepted {name}.{sig} = {v} (beyond the DBC range)")
        except Exception:  # cantools raises its EncodeError: the DBC's [min|max] holds
            c.checks += 1

    total = len(cases)
    print(f"{total} messages both ways, {n_reserved} reserved bits, {c.checks} checks; "
          f"cantools {cantools.__version__}")
    if c.failures:
        for f in c.failures[:40]:
            print("FAIL:", f)
        print(f"{len(c.failures)} failure(s)")
        return 1
    print("OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
