#!/usr/bin/env python3
"""scripts/gen-mavlink-dialect refuses definitions whose CRC_EXTRA it cannot reproduce.

Usage: mavlink_dialect_generator_test.py GENERATOR DEFINITIONS_DIR

Copies the package's files the generator reads (package.json, magic-numbers.js, minimal.js,
standard.js, common.js) into a temporary folder, then:
  1. unchanged: the generator writes RAW_IMU (27) with CRC_EXTRA 144;
  2. a field renamed in RAW_IMU (xacc -> xaccel, the package's own CRC_EXTRA left): refused,
     naming RAW_IMU: the computed value depends on the fields;
  3. RAW_IMU's CRC_EXTRA changed to 145 in both the class and magic-numbers.js (the two
     package values agree with each other, not with the fields): refused;
  4. two base fields of RAW_IMU swapped in wire order (offsets kept): refused, out of order;
  5. the extension field `id` marked as a base field: refused.
Exit 0 when every case behaves, 1 otherwise. Standard library only.
"""
import os
import shutil
import subprocess
import sys
import tempfile

DIALECTS = "minimal,standard,common"
FILES = ["magic-numbers.js", "minimal.js", "standard.js", "common.js"]
XACC = "new mavlink_1.MavLinkPacketField('xacc', 'xacc', 8, false, 2, 'int16_t', ''),"
TIME = "new mavlink_1.MavLinkPacketField('time_usec', 'timeUsec', 0, false, 8, 'uint64_t', 'us'),"
ID_EXT = "new mavlink_1.MavLinkPacketField('id', 'id', 26, true, 1, 'uint8_t', ''),"


def copy_package(src, dst):
    os.makedirs(os.path.join(dst, "dist", "lib"))
    shutil.copy(os.path.join(src, "package.json"), dst)
    for name in FILES:
        shutil.copy(os.path.join(src, "dist", "lib", name), os.path.join(dst, "dist", "lib"))


def edit(root, name, old, new):
    path = os.path.join(root, "dist", "lib", name)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if text.count(old) != 1:
        raise SystemExit(f"{name}: expected exactly one {old!r}")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace(old, new))


def run(generator, root):
    out = os.path.join(root, "table.inc")
    p = subprocess.run([sys.executable, generator, "--definitions", root, "--dialects", DIALECTS,
                        "--out", out], capture_output=True, text=True)
    table = ""
    if os.path.exists(out):
        with open(out, encoding="utf-8") as f:
            table = f.read()
    return p.returncode, p.stderr, table


def main():
    generator, definitions = sys.argv[1], sys.argv[2]
    failures = []

    def case(label, edits, expect_ok, expect_text):
        with tempfile.TemporaryDirectory() as root:
            copy_package(definitions, root)
            for name, old, new in edits:
                edit(root, name, old, new)
            code, err, table = run(generator, root)
            text = table if expect_ok else err
            if (code == 0) != expect_ok or expect_text not in text or (not expect_ok and table):
                failures.append(f"{label}: exit {code}, stderr {err!r}")
            else:
                print(f"ok: {label}")

    case("unchanged definitions", [], True, '{27, "RAW_IMU", 144, 26, 29, 2}')
    case("a field renamed", [("common.js", XACC, XACC.replace("('xacc'", "('xaccel'"))], False,
         "RAW_IMU (id 27): computed CRC_EXTRA")
    case("both package values changed",
         [("common.js", "RawImu.MAGIC_NUMBER = 144;", "RawImu.MAGIC_NUMBER = 145;"),
          ("magic-numbers.js", "'27': 144,", "'27': 145,")], False,
         "RAW_IMU (id 27): computed CRC_EXTRA 144, the class says 145")
    case("base fields out of wire order",
         [("common.js", TIME + "\n    " + XACC,
           XACC.replace(", 8, ", ", 0, ") + "\n    " + TIME.replace(", 0, ", ", 2, "))], False,
         "not in wire order")
    case("an extension marked as a base field",
         [("common.js", ID_EXT, ID_EXT.replace("true", "false"))], False,
         "RAW_IMU (id 27)")
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
