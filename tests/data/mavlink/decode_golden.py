#!/usr/bin/env python3
"""Independent golden-data decoder for MAVLink telemetry logs (.tlog), standard library only.

Written separately from plumb's C++ reader (lib/plumb/io/mavlink/mavlink_*) to produce the
JSON files the C++ tests compare against. It is NOT run by the tests.

Usage:  python3 decode_golden.py LOG.tlog [LOG2.tlog ...] --out-dir DIR
Writes DIR/<basename>.golden.json for each log.

Format: records of [8-byte big-endian uint64 unix time in microseconds][MAVLink frame].
  v1 frame: 0xFE len seq sysid compid msgid payload[len] crc_lo crc_hi
  v2 frame: 0xFD len incompat compat seq sysid compid msgid[3, little endian] payload[len]
            crc_lo crc_hi [13-byte signature if incompat & 1]; a short payload is zero-extended.
  CRC: X.25 (CRC-16/MCRF4XX), computed here bit by bit, over the bytes after the start byte up
  to the end of the payload, then the message's CRC_EXTRA byte.
Rules (the contract the C++ reader documents):
  * a record starts at a plausible time (2000-01-01 <= t < 2100-01-01) followed by 0xFE/0xFD
    (v2 with incompat flags other than bit 0 is not a start);
  * messages with a known CRC_EXTRA are accepted only when the CRC matches (else counted as a
    CRC failure and the scan moves on by one byte);
  * other ids are accepted unchecked when the next record starts right after the frame (or
    the file ends there);
  * other bytes are skipped one by one; a frame cut by the end of the file is the truncated
    last record.
"""
import argparse
import json
import os
import struct

T_MIN = 946684800 * 1000000
T_MAX = 4102444800 * 1000000

# msgid -> (name, CRC_EXTRA), typed here (the C++ reader generates its table from the definitions):
# common.xml (the generated C headers' *_CRC values) and the ardupilotmega.xml ids this log holds.
CHECKED = {
    0: ("HEARTBEAT", 50), 1: ("SYS_STATUS", 124), 2: ("SYSTEM_TIME", 137),
    21: ("PARAM_REQUEST_LIST", 159), 22: ("PARAM_VALUE", 220), 24: ("GPS_RAW_INT", 24),
    26: ("SCALED_IMU", 170), 27: ("RAW_IMU", 144), 29: ("SCALED_PRESSURE", 115),
    30: ("ATTITUDE", 39), 33: ("GLOBAL_POSITION_INT", 104), 35: ("RC_CHANNELS_RAW", 244),
    36: ("SERVO_OUTPUT_RAW", 222), 42: ("MISSION_CURRENT", 28),
    62: ("NAV_CONTROLLER_OUTPUT", 183), 65: ("RC_CHANNELS", 118),
    66: ("REQUEST_DATA_STREAM", 148), 74: ("VFR_HUD", 20),
    87: ("POSITION_TARGET_GLOBAL_INT", 150), 105: ("HIGHRES_IMU", 93),
    116: ("SCALED_IMU2", 76), 125: ("POWER_STATUS", 203), 129: ("SCALED_IMU3", 46),
    137: ("SCALED_PRESSURE2", 195), 241: ("VIBRATION", 90), 253: ("STATUSTEXT", 83),
    # ardupilotmega.xml (the generated C headers' *_CRC values, as for common.xml).
    150: ("SENSOR_OFFSETS", 134), 152: ("MEMINFO", 208), 163: ("AHRS", 127),
    165: ("HWSTATUS", 21), 168: ("WIND", 1), 182: ("AHRS3", 229),
    193: ("EKF_STATUS_REPORT", 71),
}

# Decoded payloads: msgid -> (full length, struct format, field names). Wire order: by size,
# largest first; extensions last.
LAYOUT = {
    0: (9, "<IBBBBB", "custom_mode type autopilot base_mode system_status mavlink_version"),
    22: (25, "<fHH16sB", "param_value param_count param_index param_id param_type"),
    24: (52, "<QiiiHHHHBBiIIIIH",
         "time_usec lat lon alt eph epv vel cog fix_type satellites_visible "
         "alt_ellipsoid h_acc v_acc vel_acc hdg_acc yaw"),
    27: (29, "<Q9hBh", "time_usec xacc yacc zacc xgyro ygyro zgyro xmag ymag zmag id temperature"),
    26: (24, "<I9hh", "time_boot_ms xacc yacc zacc xgyro ygyro zgyro xmag ymag zmag temperature"),
    116: (24, "<I9hh", "time_boot_ms xacc yacc zacc xgyro ygyro zgyro xmag ymag zmag temperature"),
    129: (24, "<I9hh", "time_boot_ms xacc yacc zacc xgyro ygyro zgyro xmag ymag zmag temperature"),
}


def x25(data, crc=0xFFFF):
    for byte in data:
        tmp = (byte ^ (crc & 0xFF)) & 0xFF
        tmp = (tmp ^ (tmp << 4)) & 0xFF
        crc = ((crc >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4)) & 0xFFFF
    return crc


def frame_at(buf, pos):
    """Returns (verdict, info): verdict in 'none', 'short', 'crc', 'ok', 'unchecked'."""
    if len(buf) - pos < 9:
        return "short", None
    (t,) = struct.unpack_from(">Q", buf, pos)
    if not (T_MIN <= t < T_MAX):
        return "none", None
    f = pos + 8
    stx = buf[f]
    if stx == 0xFE:
        if len(buf) - f < 6:
            return "short", None
        ln, sysid, compid, msgid = buf[f + 1], buf[f + 3], buf[f + 4], buf[f + 5]
        hdr, sig = 6, 0
    elif stx == 0xFD:
        if len(buf) - f < 3:
            return "short", None
        if buf[f + 2] & ~1:
            return "none", None
        if len(buf) - f < 10:
            return "short", None
        ln, sysid, compid = buf[f + 1], buf[f + 5], buf[f + 6]
        msgid = buf[f + 7] | (buf[f + 8] << 8) | (buf[f + 9] << 16)
        hdr, sig = 10, (13 if buf[f + 2] & 1 else 0)
    else:
        return "none", None
    total = hdr + ln + 2 + sig
    if len(buf) - f < total:
        return "short", None
    payload = bytes(buf[f + hdr:f + hdr + ln])
    info = dict(t=t, msgid=msgid, sysid=sysid, compid=compid, payload=payload,
                size=8 + total, v2=(stx == 0xFD))
    if msgid not in CHECKED:
        return "unchecked", info
    crc = x25(bytes(buf[f + 1:f + hdr + ln]) + bytes([CHECKED[msgid][1]]))
    (sent,) = struct.unpack_from("<H", buf, f + hdr + ln)
    return ("ok" if crc == sent else "crc"), info


def next_plausible(buf, pos):
    if len(buf) - pos < 9:
        return True
    (t,) = struct.unpack_from(">Q", buf, pos)
    return T_MIN <= t < T_MAX and buf[pos + 8] in (0xFE, 0xFD)


def decode(buf):
    out = dict(size_bytes=len(buf), frames_v1=0, frames_v2=0, crc_failures=0, bytes_skipped=0,
               unchecked_frames=0, truncated_bytes=0, message_counts={}, records={})
    pos = 0
    last_end = 0
    while pos < len(buf):
        verdict, info = frame_at(buf, pos)
        if verdict == "ok" or (verdict == "unchecked" and next_plausible(buf, pos + info["size"])):
            mid = info["msgid"]
            out["frames_v2" if info["v2"] else "frames_v1"] += 1
            out["message_counts"][str(mid)] = out["message_counts"].get(str(mid), 0) + 1
            if verdict == "unchecked":
                out["unchecked_frames"] += 1
            elif mid in LAYOUT:
                full, fmt, names = LAYOUT[mid]
                payload = info["payload"][:full].ljust(full, b"\0")
                rec = dict(zip(names.split(), struct.unpack(fmt, payload)))
                rec["log_time_s"] = info["t"] * 1e-6
                rec["sysid"], rec["compid"] = info["sysid"], info["compid"]
                out["records"].setdefault(mid, []).append(rec)
            pos += info["size"]
            last_end = pos
            continue
        if verdict == "crc":
            out["crc_failures"] += 1
        if verdict == "short":
            # Any valid record further on?
            later = None
            for q in range(pos + 1, len(buf)):
                v2, i2 = frame_at(buf, q)
                if v2 == "ok" or (v2 == "unchecked" and next_plausible(buf, q + i2["size"])):
                    later = q
                    break
            if later is None:
                if len(buf) - pos < 9 and pos != last_end:
                    out["bytes_skipped"] += len(buf) - pos
                else:
                    out["truncated_bytes"] = len(buf) - pos
                break
            out["bytes_skipped"] += later - pos
            pos = later
            continue
        out["bytes_skipped"] += 1
        pos += 1
    return out


def imu_sample(rec, time_key):
    scale = 1000 if time_key == "time_boot_ms" else 1
    return dict(log_time_s=rec["log_time_s"], time_us=rec[time_key] * scale,
                acc=[rec["xacc"], rec["yacc"], rec["zacc"]],
                gyr=[rec["xgyro"], rec["ygyro"], rec["zgyro"]],
                mag=[rec["xmag"], rec["ymag"], rec["zmag"]],
                temperature_cdegc=rec["temperature"], id=rec.get("id", 0),
                sysid=rec["sysid"], compid=rec["compid"])


def gps_sample(rec):
    return dict(log_time_s=rec["log_time_s"], time_us=rec["time_usec"], lat_e7=rec["lat"],
                lon_e7=rec["lon"], alt_mm=rec["alt"], fix_type=rec["fix_type"],
                satellites_visible=rec["satellites_visible"])


def summarise(d):
    recs = d.pop("records")
    g = dict(d)
    for mid, name, key in ((27, "RAW_IMU", "time_usec"), (26, "SCALED_IMU", "time_boot_ms"),
                           (116, "SCALED_IMU2", "time_boot_ms"),
                           (129, "SCALED_IMU3", "time_boot_ms")):
        rs = recs.get(mid, [])
        g[name] = dict(count=len(rs))
        if rs:
            g[name]["first"] = imu_sample(rs[0], key)
            g[name]["last"] = imu_sample(rs[-1], key)
    gps = recs.get(24, [])
    g["GPS_RAW_INT"] = dict(count=len(gps))
    if gps:
        g["GPS_RAW_INT"]["first"] = gps_sample(gps[0])
        g["GPS_RAW_INT"]["last"] = gps_sample(gps[-1])
        fixed = [r for r in gps if r["fix_type"] >= 3]
        g["GPS_RAW_INT"]["fix3d_count"] = len(fixed)
    hb = recs.get(0, [])
    g["HEARTBEAT"] = sorted({(r["sysid"], r["compid"], r["autopilot"], r["type"]) for r in hb})
    params = {}
    for r in recs.get(22, []):
        name = r["param_id"].split(b"\0")[0].decode("latin-1")
        params[name] = r["param_value"]
    g["param_count"] = len(params)
    wanted = ["INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X",
              "INS_ACCSCAL_Y", "INS_ACCSCAL_Z", "INS_GYROFFS_X", "INS_GYROFFS_Y",
              "INS_GYROFFS_Z", "INS_ACC2OFFS_Z", "INS_ACC2SCAL_Z", "INS_GYR2OFFS_X",
              "INS_ACC3OFFS_Y", "INS_ACC3SCAL_X", "INS_GYR3OFFS_Z", "AHRS_ORIENTATION",
              "SYSID_THISMAV"]
    g["params"] = {k: params[k] for k in wanted if k in params}
    return g


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("logs", nargs="+")
    ap.add_argument("--out-dir", required=True)
    args = ap.parse_args()
    for path in args.logs:
        with open(path, "rb") as f:
            buf = f.read()
        g = summarise(decode(buf))
        out = os.path.join(args.out_dir, os.path.basename(path) + ".golden.json")
        with open(out, "w") as f:
            json.dump(g, f, indent=1, sort_keys=True)
            f.write("\n")
        print(out)


if __name__ == "__main__":
    main()
