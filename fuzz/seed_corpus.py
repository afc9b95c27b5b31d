#!/usr/bin/env python3
"""Writes the seed corpus of each fuzz target (fuzz/corpus/<target>/) from a
real session's LCM log and the project's own text files.

    fuzz/seed_corpus.py SESSION_DIR

A few messages of each channel are taken as they were sent (first, middle,
last); the text files get the selector byte their target expects
(fuzz_text_files: 0 config, 1 timeline, 2 lab file, 3 checkpoint;
fuzz_small_messages: 0 telemetry, 1 status, 2 control)."""
import hashlib
import os
import struct
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")


def events(path):
    with open(path, "rb") as f:
        data = f.read()
    i = 0
    while i + 28 <= len(data):
        sync, _num, _ts, clen, dlen = struct.unpack(">IqqII", data[i:i + 28])
        if sync != 0xEDA1DA01:
            raise SystemExit(f"{path}: bad sync word at {i}")
        i += 28
        channel = data[i:i + clen].decode()
        i += clen
        yield channel, data[i:i + dlen]
        i += dlen


def put(target, blob):
    d = os.path.join(CORPUS, target)
    os.makedirs(d, exist_ok=True)
    name = hashlib.sha1(blob).hexdigest()
    with open(os.path.join(d, name), "wb") as f:
        f.write(blob)


def pick(lst):
    if not lst:
        return []
    idx = sorted({0, len(lst) // 3, len(lst) // 2, 2 * len(lst) // 3, len(lst) - 1})
    return [lst[k] for k in idx]


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    by = {}
    for ch, blob in events(os.path.join(sys.argv[1], "lcmlog")):
        by.setdefault(ch, []).append(blob)

    def channel(prefix):
        out = []
        for ch, blobs in by.items():
            if ch.startswith(prefix):
                out += blobs
        return out
    inputs = channel("RMS_OPERATOR_INPUT")
    for b in pick(inputs):
        put("fuzz_operator_input", b)
    if len(inputs) > 3:  # a sequence: next, stale, duplicate
        sep = b"\xff\xfe"
        put("fuzz_operator_input", inputs[10] + sep + inputs[11] + sep + inputs[5] + sep + inputs[11])
    for b in pick(channel("RMS_DCP_FRAME")):
        put("fuzz_dcp_frame", b)
    for b in pick(channel("RMS_ESG_FRAME")):
        put("fuzz_esg_frame", b)
    for b in pick(channel("RMS_DCP_TELEMETRY")):
        put("fuzz_small_messages", b"\x00" + b)
    for b in pick(channel("RMS_STATUS"))[:3]:
        put("fuzz_small_messages", b"\x01" + b)
    for b in pick(channel("RMS_CONTROL")):
        put("fuzz_small_messages", b"\x02" + b)
    texts = [(0, "config/rmslab.toml"), (2, "config/lab.toml")]
    for name in sorted(os.listdir(os.path.join(ROOT, "scripts", "timelines"))):
        texts.append((1, os.path.join("scripts", "timelines", name)))
    for sel, rel in texts:
        with open(os.path.join(ROOT, rel), "rb") as f:
            put("fuzz_text_files", bytes([sel]) + f.read())
    cp = os.path.join(sys.argv[1], "checkpoint.json")
    if os.path.exists(cp):
        with open(cp, "rb") as f:
            put("fuzz_text_files", b"\x03" + f.read())


if __name__ == "__main__":
    main()
