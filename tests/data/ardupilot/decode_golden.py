#!/usr/bin/env python3
"""Independent golden-data decoder for ArduPilot DataFlash .bin logs (standard library only).

Written separately from plumb's C++ reader (lib/plumb/io/dataflash.cc) to produce the JSON
files the C++ tests compare against. It is NOT run by the tests.

Usage:  python3 decode_golden.py LOG.bin [LOG2.bin ...] --out-dir DIR
Writes DIR/<basename>.golden.json for each log.

Decoding rules (the same contract the C++ reader documents):
  * A record is 0xA3 0x95 <type> followed by (length - 3) body bytes, where length comes from
    the FMT record (type 128) that defined <type>. FMT itself is built in: 89 bytes, 'BBnNZ'.
  * The first FMT seen for a type wins; a later, different FMT for the same type is ignored.
  * Bytes that do not start a record of a known type are skipped one at a time (counted).
  * A record whose header is found but whose length runs past the end of the file is the
    truncated last record: it is dropped and decoding stops.
  * The FMT length is trusted: fields are decoded while they fit in the body; extra body bytes
    are ignored.
  * Fewer than 3 bytes left at the end: a truncated record when they are a prefix of the
    header (0xA3 or 0xA3 0x95), otherwise skipped bytes.
  * fmt_length_mismatches counts accepted FMTs whose field sizes do not add up to length - 3.
IMU series: instance k is the rows of 'IMU' with I == k when 'IMU' has a column 'I', otherwise
the rows of 'IMU' (k = 0) or 'IMU<k+1>'. Time t_s = TimeUS * 1e-6 or TimeMS * 1e-3; samples
whose time is not finite, does not exceed the previous kept sample's, or is not below the
next row's time (a corrupted spike) are dropped.
"""
import argparse
import json
import math
import os
import struct

HEAD = b"\xa3\x95"
FMT_TYPE = 128

# format char -> (struct code, size, scale or None)
CHARS = {
    "b": ("b", 1, None), "B": ("B", 1, None), "h": ("h", 2, None), "H": ("H", 2, None),
    "i": ("i", 4, None), "I": ("I", 4, None), "f": ("f", 4, None), "d": ("d", 8, None),
    "n": ("4s", 4, None), "N": ("16s", 16, None), "Z": ("64s", 64, None),
    "c": ("h", 2, 0.01), "C": ("H", 2, 0.01), "e": ("i", 4, 0.01), "E": ("I", 4, 0.01),
    "L": ("i", 4, 1e-7), "M": ("B", 1, None), "q": ("q", 8, None), "Q": ("Q", 8, None),
    "a": ("64s", 64, None),
}


def cstr(raw):
    i = raw.find(b"\0")
    if i >= 0:
        raw = raw[:i]
    return raw.decode("latin-1")


class Fmt:
    def __init__(self, type_id, length, name, fmt, columns):
        self.type_id = type_id
        self.length = length
        self.name = name
        self.fmt = fmt
        self.columns = columns.split(",") if columns else []
        self.decodable = all(c in CHARS for c in fmt)

    def decode(self, body):
        """Returns {column: value} for the fields that fit in body."""
        out = {}
        off = 0
        for k, c in enumerate(self.fmt):
            code, size, scale = CHARS[c]
            if off + size > len(body):
                break
            (v,) = struct.unpack_from("<" + code, body, off)
            off += size
            if c in "nNZ":
                v = cstr(v)
            elif c == "a":
                v = list(struct.unpack("<32h", v))
            elif scale is not None:
                v = v * scale
            name = self.columns[k] if k < len(self.columns) else "col%d" % k
            out[name] = v
        return out


def decode(path):
    data = open(path, "rb").read()
    n = len(data)
    formats = {FMT_TYPE: Fmt(FMT_TYPE, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")}
    counts = {}
    rows = {}  # name -> list of decoded dicts (only for the types we keep)
    keep = lambda name: name.startswith("IMU") or name in ("PARM", "ISBH", "GPS")
    skipped = 0
    truncated_records = 0
    truncated_bytes = 0
    fmt_length_mismatches = 0
    pos = 0
    while True:
        if pos + 3 > n:
            tail = data[pos:]
            if tail and HEAD.startswith(tail):
                truncated_records += 1
                truncated_bytes += len(tail)
            else:
                skipped += len(tail)
            break
        t = data[pos + 2]
        if data[pos:pos + 2] != HEAD or t not in formats:
            skipped += 1
            pos += 1
            continue
        f = formats[t]
        if pos + f.length > n:
            truncated_records += 1
            truncated_bytes += n - pos
            break
        body = data[pos + 3:pos + f.length]
        pos += f.length
        counts[f.name] = counts.get(f.name, 0) + 1
        if not f.decodable:
            continue
        if t == FMT_TYPE:
            d = f.decode(body)
            if d["Length"] >= 3 and d["Type"] not in formats:
                nf = Fmt(d["Type"], d["Length"], d["Name"], d["Format"], d["Columns"])
                formats[d["Type"]] = nf
                if nf.decodable and sum(CHARS[c][1] for c in nf.fmt) != nf.length - 3:
                    fmt_length_mismatches += 1
        if keep(f.name):
            rows.setdefault(f.name, []).append(f.decode(body))
    return (data, counts, rows, skipped, truncated_records, truncated_bytes,
            fmt_length_mismatches)


def imu_instances(rows):
    """Returns {instance: [row dicts]} following the rule in the module docstring."""
    out = {}
    imu = rows.get("IMU", [])
    if imu and "I" in imu[0]:
        for r in imu:
            out.setdefault(int(r["I"]), []).append(r)
        return out
    if imu:
        out[0] = imu
    for k in range(1, 10):
        r = rows.get("IMU%d" % (k + 1))
        if r:
            out[k] = r
    return out


def sample(r):
    t = r["TimeUS"] * 1e-6 if "TimeUS" in r else r["TimeMS"] * 1e-3
    temp = r.get("T", r.get("Temp"))
    return {
        "t_s": t,
        "acc": [r["AccX"], r["AccY"], r["AccZ"]],
        "gyr": [r["GyrX"], r["GyrY"], r["GyrZ"]],
        "temp_c": temp,
    }


def imu_summary(rows):
    kept = []
    last_t = None
    samples = [sample(r) for r in rows]
    for i, s in enumerate(samples):
        if not math.isfinite(s["t_s"]):
            continue
        if i + 1 < len(samples) and not s["t_s"] < samples[i + 1]["t_s"]:
            continue
        if last_t is None or s["t_s"] > last_t:
            kept.append(s)
            last_t = s["t_s"]
    return {"samples": len(kept), "first": kept[0], "last": kept[-1]}


PARAMS_OF_INTEREST = ["INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X",
                      "INS_GYROFFS_X", "AHRS_ORIENTATION"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--out-dir", required=True)
    a = ap.parse_args()
    for path in a.logs:
        data, counts, rows, skipped, trunc, trunc_bytes, mismatches = decode(path)
        params = {}
        for r in rows.get("PARM", []):
            params[r["Name"]] = r["Value"]
        golden = {
            "file": os.path.basename(path),
            "size_bytes": len(data),
            "bytes_skipped": skipped,
            "truncated_records": trunc,
            "truncated_bytes": trunc_bytes,
            "fmt_length_mismatches": mismatches,
            "message_counts": dict(sorted(counts.items())),
            "param_count": len(params),
            "params": {k: params[k] for k in PARAMS_OF_INTEREST if k in params},
            "imu": {str(k): imu_summary(v) for k, v in sorted(imu_instances(rows).items())},
        }
        if rows.get("ISBH"):
            golden["first_isbh"] = rows["ISBH"][0]
        if rows.get("GPS"):
            g = rows["GPS"][-1]
            golden["last_gps"] = {"Lat": g["Lat"], "Lng": g["Lng"], "Alt": g["Alt"]}
        out = os.path.join(a.out_dir, os.path.basename(path) + ".golden.json")
        with open(out, "w") as fh:
            json.dump(golden, fh, indent=1, allow_nan=True)
            fh.write("\n")


if __name__ == "__main__":
    main()
