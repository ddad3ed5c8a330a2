#!/usr/bin/env python3
"""Independent golden-data decoder for PX4 ULog (.ulg) files (standard library only).

Written separately from plumb's C++ reader (lib/plumb/io/px4/ulog*.cc) to produce the JSON files
the C++ tests compare against. It is NOT run by the tests.

Usage:  python3 decode_golden.py LOG.ulg [LOG2.ulg ...] --out-dir DIR [--damaged]
Writes DIR/<basename>.golden.json for each log (with --damaged: <basename>.damaged.golden.json
for a copy with bytes XORed at fixed offsets, see damage()).

Format (PX4 "ULog File Format"): 16-byte header 'U' 'L' 'o' 'g' 0x01 0x12 0x35, version byte,
uint64 start time (us); then messages, each a uint16 size (bytes after the 3-byte header), a
type byte and the body. Types: B flag bits (8 compat, 8 incompat bytes, 3 uint64 appended
offsets), F format 'name:type field;...', I info / P parameter (uint8 key length, key
'type name', value), M info multiple (uint8 is_continued first), Q default parameter (uint8
default-type bits first), A add logged (uint8 multi_id, uint16 msg_id, name), R remove,
D data (uint16 msg_id, body), L logging (uint8 level, uint64 time, text), C tagged logging
(uint8 level, uint16 tag, uint64 time, text), S sync (8 magic bytes), O dropout (uint16 ms).

Decoding rules (the same contract the C++ reader documents):
  * Parameters: P messages before the first A, L or C are the initial values; later ones are
    changes (not in the initial table).
  * Nested formats are flattened; fields whose name starts with '_padding' are not columns
    but keep their bytes; trailing top-level padding fields need not be logged, so a D body
    is accepted when its size is between the size without and with them.
  * Appended data (incompat flag bit 0 with non-zero appended offsets): the data section is
    read in segments [data start, offset0), [offset0, offset1), ..., [last offset, end); a
    message that runs past its segment's end is that segment's truncated record (dropped).
  * Corrupt header: a size of 0, a non-letter type, a D whose size does not fit its
    subscription, an S without the sync magic or not 8 bytes, an O or R not 2 bytes, an A
    shorter than 4, an L shorter than 9, a C shorter than 11. The decoder then skips byte by
    byte (counted) until a D header with a subscribed id and a fitting size, a complete S
    message, or a chain of 4 complete non-corrupt messages of known types (fewer when the
    segment ends right after them) starts.
  * A subscription whose format cannot be resolved (unknown or circular type, empty, larger
    than 65533 bytes) is counted and leaves its id unsubscribed.
  * D with an id never subscribed: counted, skipped by its size. Unknown letter types:
    counted, skipped by their size.
"""
import argparse
import json
import os
import struct

MAGIC = b"ULog\x01\x12\x35"
SYNC = bytes([0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12])
TYPES = {
    "int8_t": ("b", 1), "uint8_t": ("B", 1), "int16_t": ("h", 2), "uint16_t": ("H", 2),
    "int32_t": ("i", 4), "uint32_t": ("I", 4), "int64_t": ("q", 8), "uint64_t": ("Q", 8),
    "float": ("f", 4), "double": ("d", 8), "bool": ("?", 1), "char": ("c", 1),
}
KNOWN = set(b"BFIMPQARDLCSO")
MAX_NEST = 32


def parse_format(text):
    name, _, rest = text.partition(":")
    fields = []
    for item in rest.split(";"):
        if not item:
            continue
        typ, _, fname = item.partition(" ")
        count = 1
        is_array = False
        if "[" in typ:
            base, _, n = typ.partition("[")
            count = int(n.rstrip("]"))
            typ = base
            is_array = True
        fields.append((typ, count, is_array, fname))
    return name, fields


class Sub:
    def __init__(self, name, multi_id, formats):
        self.name = name
        self.multi_id = multi_id
        self.columns = []  # (name, type, offset)
        self.max_size = self._flatten(name, "", 0, formats, 0)
        # trailing top-level padding need not be logged
        size_no_pad = self.max_size
        top = formats[name]
        for typ, count, _, fname in reversed(top):
            if not fname.startswith("_padding"):
                break
            size_no_pad -= self._size(typ, formats, 0) * count
        self.min_size = size_no_pad
        self.count = 0
        self.first = None
        self.last = None
        self.bodies = None

    def _size(self, typ, formats, depth):
        if typ in TYPES:
            return TYPES[typ][1]
        if depth > MAX_NEST or typ not in formats:
            raise ValueError("unresolved type " + typ)
        return sum(self._size(t, formats, depth + 1) * c for t, c, _, _ in formats[typ])

    def _flatten(self, typ, prefix, offset, formats, depth):
        if depth > MAX_NEST or typ not in formats:
            raise ValueError("unresolved type " + typ)
        for ftyp, count, is_array, fname in formats[typ]:
            for i in range(count):
                label = prefix + fname + ("[%d]" % i if is_array else "")
                if ftyp in TYPES:
                    if not fname.startswith("_padding"):
                        self.columns.append((label, ftyp, offset))
                    offset += TYPES[ftyp][1]
                else:
                    offset = self._flatten(ftyp, label + ".", offset, formats, depth + 1)
        return offset

    def decode(self, body):
        out = {}
        for name, typ, off in self.columns:
            (v,) = struct.unpack_from("<" + TYPES[typ][0], body, off)
            if typ == "char":
                v = v[0]
            elif typ == "bool":
                v = 1 if v else 0
            out[name] = v
        return out


def info_value(key, raw):
    typ = key.split(" ")[0]
    if typ.startswith("char["):
        return raw.decode("latin-1")
    if typ in TYPES and len(raw) == TYPES[typ][1]:
        (v,) = struct.unpack("<" + TYPES[typ][0], raw)
        return v
    return raw.hex()


class Log:
    def __init__(self, data):
        self.data = data
        if len(data) < 16 or data[:7] != MAGIC:
            raise ValueError("not a ULog file")
        self.version = data[7]
        (self.start_us,) = struct.unpack_from("<Q", data, 8)
        self.formats = {}
        self.subs = {}
        self.info = {}
        self.params = {}
        self.param_changes = 0
        self.default_params = 0
        self.appended = False
        self.appended_offsets = []
        self.in_defs = True
        self.w = dict(bytes_skipped=0, skip_runs=0, first_skip_offset=0, truncated_records=0, truncated_bytes=0,
                      unknown_msg_id_messages=0, unknown_type_messages=0,
                      unresolved_subscriptions=0, dropouts=0,
                      dropout_total_ms=0, sync_messages=0, logging_messages=0)
        self.last_skip = -2
        self.run()

    def skip(self, pos):
        if self.w["bytes_skipped"] == 0:
            self.w["first_skip_offset"] = pos
        if pos != self.last_skip + 1:
            self.w["skip_runs"] += 1
        self.w["bytes_skipped"] += 1
        self.last_skip = pos

    def valid_resync(self, pos, end):
        d = self.data
        if end - pos < 3:
            return False
        size, typ = struct.unpack_from("<HB", d, pos)
        if pos + 3 + size > end:
            return False
        if typ == ord("D") and size >= 2:
            (mid,) = struct.unpack_from("<H", d, pos + 3)
            s = self.subs.get(mid)
            if s is not None:
                return s.min_size <= size - 2 <= s.max_size
        if typ == ord("S"):
            return size == 8 and d[pos + 3:pos + 11] == SYNC
        at = pos
        for _ in range(4):
            if at == end:
                return True
            if end - at < 3:
                return False
            n, ty = struct.unpack_from("<HB", d, at)
            if ty not in KNOWN or self.corrupt(n, ty, at, end) or at + 3 + n > end:
                return False
            at += 3 + n
        return True

    def corrupt(self, size, typ, pos, end):
        if size == 0:
            return True
        if not (ord("A") <= typ <= ord("Z") or ord("a") <= typ <= ord("z")):
            return True
        if typ == ord("D"):
            if size < 2:
                return True
            if end - pos < 5:
                return False  # truncated: the caller decides
            (mid,) = struct.unpack_from("<H", self.data, pos + 3)
            s = self.subs.get(mid)
            if s is not None and not (s.min_size <= size - 2 <= s.max_size):
                return True
        if typ == ord("S") and size != 8:
            return True
        if typ in (ord("O"), ord("R")) and size != 2:
            return True
        if (typ == ord("A") and size < 4) or (typ == ord("L") and size < 9) or \
                (typ == ord("C") and size < 11):
            return True
        if typ == ord("S") and pos + 11 <= end and self.data[pos + 3:pos + 11] != SYNC:
            return True
        return False

    def run(self):
        d = self.data
        pos = 16
        ends = [len(d)]
        end = len(d)
        seg_index = 0
        resync = False
        while True:
            if pos >= end:
                if seg_index + 1 < len(ends):
                    seg_index += 1
                    pos = self.appended_offsets[seg_index - 1]
                    end = ends[seg_index]
                    resync = False
                    continue
                break
            if resync:
                if self.valid_resync(pos, end):
                    resync = False
                else:
                    self.skip(pos)
                    pos += 1
                    continue
            if end - pos < 3:
                self.w["truncated_records"] += 1
                self.w["truncated_bytes"] += end - pos
                pos = end
                continue
            size, typ = struct.unpack_from("<HB", d, pos)
            if self.corrupt(size, typ, pos, end):
                resync = True
                continue
            if pos + 3 + size > end:
                self.w["truncated_records"] += 1
                self.w["truncated_bytes"] += end - pos
                pos = end
                continue
            body = d[pos + 3:pos + 3 + size]
            at = pos
            pos += 3 + size
            if typ == ord("B") and at == 16 and size >= 40:
                incompat = body[8:16]
                offs = list(struct.unpack_from("<3Q", body, 16))
                while offs and offs[-1] == 0:
                    offs.pop()
                if incompat[0] & 1 and offs:
                    self.appended = True
                    good = []
                    last = pos
                    for o in offs:
                        if last <= o <= len(d):
                            good.append(o)
                            last = o
                    self.appended_offsets = good
                    ends = good + [len(d)]
                    end = ends[0]
            elif typ == ord("F"):
                name, fields = parse_format(body.decode("latin-1"))
                self.formats[name] = fields
            elif typ in (ord("I"), ord("P"), ord("M"), ord("Q")):
                b = body
                if typ in (ord("M"), ord("Q")):
                    b = b[1:]
                klen = b[0]
                key = b[1:1 + klen].decode("latin-1")
                raw = b[1 + klen:]
                if typ == ord("I"):
                    self.info[key.split(" ")[-1]] = info_value(key, raw)
                elif typ == ord("P"):
                    if self.in_defs:
                        self.params[key.split(" ")[-1]] = info_value(key, raw)
                    else:
                        self.param_changes += 1
                elif typ == ord("Q"):
                    self.default_params += 1
            elif typ == ord("A"):
                self.in_defs = False
                multi_id = body[0]
                (mid,) = struct.unpack_from("<H", body, 1)
                name = body[3:].decode("latin-1")
                if mid in self.subs:
                    continue  # an id is never reused; the first subscription stays
                try:
                    sub = Sub(name, multi_id, self.formats)
                except (ValueError, KeyError, RecursionError):
                    sub = None
                if sub is None or not 0 < sub.max_size <= 65533:
                    self.w["unresolved_subscriptions"] += 1
                else:
                    self.subs[mid] = sub
            elif typ == ord("D"):
                (mid,) = struct.unpack_from("<H", body, 0)
                s = self.subs.get(mid)
                if s is None:
                    self.w["unknown_msg_id_messages"] += 1
                else:
                    s.count += 1
                    row = body[2:]
                    if s.first is None:
                        s.first = row
                    s.last = row
                    if s.bodies is not None:
                        s.bodies.append(row)
            elif typ in (ord("L"), ord("C")):
                self.in_defs = False
                self.w["logging_messages"] += 1
            elif typ == ord("O"):
                self.w["dropouts"] += 1
                self.w["dropout_total_ms"] += struct.unpack_from("<H", body, 0)[0]
            elif typ == ord("S"):
                self.w["sync_messages"] += 1
            elif typ == ord("R"):
                pass
            elif typ not in KNOWN:
                self.w["unknown_type_messages"] += 1


IMU_TOPICS = ("sensor_combined", "sensor_accel", "sensor_gyro", "vehicle_imu")
GPS_TOPICS = ("vehicle_gps_position", "sensor_gps")
PARAM_PREFIXES = ("CAL_ACC0", "CAL_GYRO0", "SENS_BOARD_ROT", "TC_A_ENABLE", "TC_G_ENABLE")


SAMPLE_FIELDS = ("timestamp", "timestamp_sample", "gyro_rad", "gyro_rad_s", "accelerometer_m_s2",
                 "accelerometer_timestamp_relative", "device_id", "x", "y", "z", "temperature",
                 "accel_device_id", "gyro_device_id", "delta_angle", "delta_velocity",
                 "delta_angle_dt", "delta_velocity_dt")


def keep_fields(rec):
    return {k: v for k, v in rec.items() if k.split("[")[0] in SAMPLE_FIELDS}


DAMAGE_OFFSETS_FIXED = (5202, 30012, 61026)  # type bytes of an F, a P and an A header
DAMAGE_START, DAMAGE_STEP, DAMAGE_XOR = 70000, 97001, 0x5A


def damage(data):
    """The damaged copy the C++ test makes too: XOR 0x5A at offsets 5202, 30012, 61026 and
    70000 + 97001 k."""
    out = bytearray(data)
    offsets = list(DAMAGE_OFFSETS_FIXED) + list(range(DAMAGE_START, len(out), DAMAGE_STEP))
    for o in offsets:
        if o < len(out):
            out[o] ^= DAMAGE_XOR
    return bytes(out)


def damaged_golden(path):
    with open(path, "rb") as f:
        data = damage(f.read())
    log = Log(data)
    out = {"file": os.path.basename(path), "damage": "XOR 0x5A at 5202, 30012, 61026, 70000 + 97001 k",
           "size_bytes": len(data)}
    out.update(log.w)
    counts = {}
    for mid in sorted(log.subs):
        s = log.subs[mid]
        if s.count:
            key = "%s/%d" % (s.name, s.multi_id)
            counts[key] = counts.get(key, 0) + s.count
    out["topic_counts"] = counts
    out["param_count"] = len(log.params)
    out["format_count"] = len(log.formats)
    return out


def golden(path):
    with open(path, "rb") as f:
        data = f.read()
    log = Log(data)
    out = {"file": os.path.basename(path), "size_bytes": len(data), "version": log.version,
           "start_timestamp_us": log.start_us, "appended": log.appended,
           "appended_offsets": log.appended_offsets}
    out.update(log.w)
    counts = {}
    for mid in sorted(log.subs):
        s = log.subs[mid]
        if s.count:
            key = "%s/%d" % (s.name, s.multi_id)
            counts[key] = counts.get(key, 0) + s.count
    out["topic_counts"] = counts
    out["param_count"] = len(log.params)
    out["param_changes"] = log.param_changes
    out["default_params"] = log.default_params
    out["params"] = {k: v for k, v in sorted(log.params.items())
                     if k.startswith(PARAM_PREFIXES)}
    out["info"] = {k: log.info[k] for k in ("ver_hw", "sys_name", "ver_sw") if k in log.info}
    samples = {}
    for mid in sorted(log.subs):
        s = log.subs[mid]
        if s.name in IMU_TOPICS and s.count:
            samples["%s/%d" % (s.name, s.multi_id)] = {
                "count": s.count, "first": keep_fields(s.decode(s.first)),
                "last": keep_fields(s.decode(s.last))}
    out["imu_samples"] = samples
    out["gps_first_fix"] = gps_first_fix(path, log)
    return out


def gps_first_fix(path, log):
    """First record with fix_type >= 3 of the first GPS topic, decoded in full."""
    targets = {mid for mid, s in log.subs.items() if s.name in GPS_TOPICS and s.count}
    if not targets:
        return None
    # second pass keeping the GPS bodies
    log2 = Log.__new__(Log)
    with open(path, "rb") as f:
        data = f.read()
    log2.__init__(data)  # re-decode; cheap enough for golden generation
    return _first_fix_from(data, log2, targets)


def _first_fix_from(data, log, targets):
    # Re-run with bodies kept for the GPS subscriptions.
    keep = Log.__new__(Log)
    keep.data = data
    keep.version = data[7]
    (keep.start_us,) = struct.unpack_from("<Q", data, 8)
    keep.formats, keep.subs, keep.info, keep.params = {}, {}, {}, {}
    keep.param_changes = keep.default_params = 0
    keep.appended, keep.appended_offsets, keep.in_defs = False, [], True
    keep.w = dict(log.w)
    keep.w = {k: 0 for k in log.w}
    keep.last_skip = -2
    orig_init = Sub.__init__

    def init(self, name, multi_id, formats):
        orig_init(self, name, multi_id, formats)
        if name in GPS_TOPICS:
            self.bodies = []
    Sub.__init__ = init
    try:
        keep.run()
    finally:
        Sub.__init__ = orig_init
    for mid in sorted(keep.subs):
        s = keep.subs[mid]
        if s.bodies is None:
            continue
        for row in s.bodies:
            rec = s.decode(row)
            if rec.get("fix_type", 0) >= 3:
                keys = ("timestamp", "lat", "lon", "alt", "latitude_deg", "longitude_deg",
                        "altitude_msl_m", "fix_type")
                return dict({"topic": s.name, "multi_id": s.multi_id},
                            **{k: rec[k] for k in keys if k in rec})
    return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--damaged", action="store_true",
                    help="write <log>.damaged.golden.json for the damaged copy (see damage())")
    args = ap.parse_args()
    for path in args.logs:
        g = damaged_golden(path) if args.damaged else golden(path)
        suffix = ".damaged.golden.json" if args.damaged else ".golden.json"
        out = os.path.join(args.out_dir, os.path.basename(path) + suffix)
        with open(out, "w") as f:
            json.dump(g, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
