#!/usr/bin/env python3
"""Independent golden-data decoder for ArduPilot DataFlash logs, binary .bin and text .log
(standard library only).

Written separately from plumb's C++ reader (lib/plumb/io/dataflash.cc) to produce the JSON
files the C++ tests compare against. It is NOT run by the tests.

Usage:  python3 decode_golden.py LOG.bin [LOG2.log ...] --out-dir DIR
Writes DIR/<basename>.golden.json for each log; a name ending in .log is read as a text log
(rules in the "text logs" section below).

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

    def columns_fitting(self):
        """(name, format char, size) of the leading known fields that fit in length - 3."""
        out = []
        off = 0
        for k, c in enumerate(self.fmt):
            if c not in CHARS:
                break
            size = CHARS[c][1]
            if off + size <= self.length - 3:
                out.append((self.columns[k] if k < len(self.columns) else "col%d" % k, c, size))
            off += size
        return out

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
    keep = lambda name: name.startswith("IMU") or name in ("PARM", "ISBH", "ISBD", "GPS")
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


# ---- text logs (.log) ----------------------------------------------------------------------
#
# Text rules (the contract documented for plumb's ParseDataflashText):
#  * Lines end at '\n' (a '\r' before it is dropped); surrounding spaces/tabs are stripped;
#    blank lines are ignored. Non-blank lines before the first line whose first field is
#    "FMT" are header lines (counted, ignored).
#  * Fields are split at every ',' and stripped. The first field names the message; it must
#    have been defined by an accepted FMT line (FMT itself is built in).
#  * A message needs exactly one value per format character (trailing empty fields beyond
#    that are dropped); when the last format character is n/N/Z, extra fields belong to it:
#    its value is the rest of the line from where that field starts (commas kept).
#  * Each value must fit its format character: integers integral and in range (M may be a
#    name: stored as 255), c/C/e/E stored as round(v*100), L as round(v*1e7) (round half
#    away from zero) in range, f a finite value in float range or NaN/inf, text truncated to
#    the field width. Otherwise the line is bad (counted, first line number kept) and dropped.
#  * Only the fields that fit the FMT length are kept (same as the binary rule).
#  * FMT lines additionally need a name of 1..4 characters and a format of up to 16; the
#    column list is the fields after the format, joined with ',' without trailing empty ones.
#    A type id or a name that is already defined is not redefined; length < 3 defines nothing.
# Values are then read back exactly as the binary decoder reads them (struct round trip).

FLOAT_MAX = 3.4028234663852886e38


def round_half_away(x):
    return int(math.copysign(math.floor(abs(x) + 0.5), x))


INT_RANGES = {"b": (-128, 127), "B": (0, 255), "M": (0, 255), "h": (-32768, 32767),
              "H": (0, 65535), "i": (-2 ** 31, 2 ** 31 - 1), "I": (0, 2 ** 32 - 1),
              "q": (-2 ** 63, 2 ** 63 - 1), "Q": (0, 2 ** 64 - 1)}
SCALED = {"c": ("h", 100.0), "C": ("H", 100.0), "e": ("i", 100.0), "E": ("I", 100.0),
          "L": ("i", 1e7)}


def parse_float(text):
    try:
        if "_" in text:
            return None
        return float(text)
    except ValueError:
        return None


def encode_text_field(c, text):
    """Returns (value as the binary reader would return it, mode_name flag) or None."""
    if c == "M" and parse_float(text) is None:
        # a flight-mode name ("Stabilize"): stored as 255
        return (255, True) if text != "" else None
    if c in INT_RANGES:
        lo, hi = INT_RANGES[c]
        v = None
        if c in "qQ":
            try:
                v = int(text)
            except ValueError:
                v = None
        if v is None:
            f = parse_float(text)
            if f is not None and math.isfinite(f) and f == math.floor(f):
                v = int(f)
        if v is None or v < lo or v > hi:
            return None
        return v, False
    if c in SCALED:
        code, inv = SCALED[c]
        f = parse_float(text)
        if f is None or not math.isfinite(f):
            return None
        stored = round_half_away(f * inv)
        lo, hi = INT_RANGES[code]
        if stored < lo or stored > hi:
            return None
        return stored * CHARS[c][2], False
    if c == "f":
        f = parse_float(text)
        if f is None or (math.isfinite(f) and abs(f) > FLOAT_MAX):
            return None
        return struct.unpack("<f", struct.pack("<f", f))[0], False
    if c == "d":
        f = parse_float(text)
        return (None if f is None else (f, False))
    if c in "nNZ":
        raw = text.encode("latin-1")[:CHARS[c][1]]
        return cstr(raw), False
    if c == "a":
        return [0] * 32, False
    return None


def decode_text(path):
    data = open(path, "rb").read()
    types = {"FMT": Fmt(FMT_TYPE, 89, "FMT", "BBnNZ", "Type,Length,Name,Format,Columns")}
    ids = {FMT_TYPE}
    counts = {}
    rows = {}
    keep = lambda name: name.startswith("IMU") or name in ("PARM", "GPS")
    header_lines = 0
    bad_lines = 0
    first_bad = 0
    mode_names = 0
    seen_fmt = False
    for number, raw in enumerate(data.split(b"\n"), start=1):
        if raw.endswith(b"\r"):
            raw = raw[:-1]
        line = raw.decode("latin-1").strip(" \t")
        if not line:
            continue
        fields = [x.strip(" \t") for x in line.split(",")]
        if not seen_fmt:
            if fields[0] != "FMT":
                header_lines += 1
                continue
            seen_fmt = True
        f = types.get(fields[0])
        ok = f is not None
        if ok:
            values = fields[1:]
            known = f.decodable
            expected = len(f.fmt) if known else len(f.columns_fitting())
            while len(values) > expected and values[-1] == "":
                values.pop()
            if known and expected > 0 and f.fmt[-1] in "nNZ" and len(values) > expected:
                # the rest of the line from the start of that field
                starts = [0]
                for k, ch in enumerate(line):
                    if ch == ",":
                        starts.append(k + 1)
                values = values[:expected - 1] + [line[starts[expected]:].strip(" \t")]
            ok = (len(values) == expected) if known else (len(values) >= expected)
        decoded = {}
        mode = False
        if ok:
            for k, (name, c, size) in enumerate(f.columns_fitting()):
                r = encode_text_field(c, values[k])
                if r is None:
                    ok = False
                    break
                decoded[name] = r[0]
                mode = mode or r[1]
        if ok and f.name == "FMT":
            ok = 1 <= len(values[2]) <= 4 and len(values[3]) <= 16
        if not ok:
            bad_lines += 1
            if first_bad == 0:
                first_bad = number
            continue
        if mode:
            mode_names += 1
        counts[f.name] = counts.get(f.name, 0) + 1
        if keep(f.name):
            rows.setdefault(f.name, []).append(decoded)
        if f.name == "FMT":
            type_id, length, name, fmt = int(values[0]), int(values[1]), values[2], values[3]
            cols = fields[5:]
            while cols and cols[-1] == "":
                cols.pop()
            if length >= 3 and type_id not in ids and name not in types:
                types[name] = Fmt(type_id, length, name, fmt, ",".join(cols))
                ids.add(type_id)
    return {
        "data": data, "counts": counts, "rows": rows, "header_lines": header_lines,
        "bad_lines": bad_lines, "first_bad_line": first_bad, "mode_names": mode_names,
        "types": types,
    }


def isbd_streams(headers, data):
    """Batch-sampler samples per (sensor type, instance): an ISBD row belongs to the latest
    ISBH with the same N written (TimeUS) at or before it; sample j = seqno * 32 + k of the
    batch (j < smp_cnt) is at SampleUS * 1e-6 + j / smp_rate s with value int16 / mul.
    Returns {"<type>/<instance>": {samples, first, last}} (t_s, xyz)."""
    out = {}
    for want in sorted({(h["type"], h["instance"]) for h in headers}):
        samples = []
        for hi, h in enumerate(headers):
            if (h["type"], h["instance"]) != want:
                continue
            batch = {}
            for d in data:
                owner = None
                for hj, h2 in enumerate(headers):
                    if h2["N"] == d["N"] and h2["TimeUS"] <= d["TimeUS"]:
                        owner = hj
                if owner != hi:
                    continue
                for k in range(32):
                    j = d["seqno"] * 32 + k
                    if j < h["smp_cnt"]:
                        m = struct.unpack("<f", struct.pack("<f", h["mul"]))[0]
                        batch[j] = [float(struct.unpack("<f", struct.pack("<f", d[a][k] / m))[0])
                                    for a in ("x", "y", "z")]
            for j in sorted(batch):
                samples.append({"t_s": h["SampleUS"] * 1e-6 + j / h["smp_rate"], "xyz": batch[j]})
        samples.sort(key=lambda x: x["t_s"])
        out["%d/%d" % want] = {"samples": len(samples), "first": samples[0],
                               "last": samples[-1]} if samples else {"samples": 0}
    return out


PARAMS_OF_INTEREST = ["INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X",
                      "INS_GYROFFS_X", "AHRS_ORIENTATION"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--out-dir", required=True)
    a = ap.parse_args()
    for path in a.logs:
        if path.lower().endswith(".log"):
            write_text_golden(path, a.out_dir)
            continue
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
            golden["isbd"] = isbd_streams(rows["ISBH"], rows.get("ISBD", []))
        if rows.get("GPS"):
            g = rows["GPS"][-1]
            golden["last_gps"] = {"Lat": g["Lat"], "Lng": g["Lng"], "Alt": g["Alt"]}
        out = os.path.join(a.out_dir, os.path.basename(path) + ".golden.json")
        with open(out, "w") as fh:
            json.dump(golden, fh, indent=1, allow_nan=True)
            fh.write("\n")


def write_text_golden(path, out_dir):
    d = decode_text(path)
    rows = d["rows"]
    params = {}
    for r in rows.get("PARM", []):
        params[r["Name"]] = r["Value"]
    imu = {}
    for k, v in sorted(imu_instances(rows).items()):
        imu[str(k)] = imu_summary(v)
    golden = {
        "file": os.path.basename(path),
        "size_bytes": len(d["data"]),
        "text_header_lines": d["header_lines"],
        "text_bad_lines": d["bad_lines"],
        "text_first_bad_line": d["first_bad_line"],
        "text_mode_names": d["mode_names"],
        "message_counts": dict(sorted(d["counts"].items())),
        "param_count": len(params),
        # NaN (not valid JSON) is written as the string "NaN"
        "params": {k: (params[k] if math.isfinite(params[k]) else "NaN")
                   for k in PARAMS_OF_INTEREST + NAN_PARAMS if k in params},
        "imu": imu,
        # IMU messages defined by an FMT but without a single row
        "imu_defined_without_rows": sorted(
            n for n in d["types"] if n.startswith("IMU") and n not in d["counts"]),
    }
    if rows.get("GPS"):
        g = rows["GPS"][-1]
        golden["last_gps"] = {"Lat": g["Lat"], "Lng": g["Lng"], "Alt": g["Alt"]}
    out = os.path.join(out_dir, os.path.basename(path) + ".golden.json")
    with open(out, "w") as fh:
        json.dump(golden, fh, indent=1, allow_nan=True)
        fh.write("\n")


NAN_PARAMS = ["COMPASS_MOT_X", "COMPASS_MOT_Y", "COMPASS_MOT_Z"]


if __name__ == "__main__":
    main()
