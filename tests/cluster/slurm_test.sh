#!/usr/bin/env bash
# tests/cluster/slurm_test.sh PLUMB REPO: a study as a Slurm job array (scripts/sweep-slurm) on a
# single-node Slurm started for the test (scripts/slurm-local) equals `plumb sweep` in one
# process, file for file, byte for byte; a study plumb refuses is said before anything is
# submitted; a shard failing on its node cancels the merge job, no result is written and the
# failed shard's log is shown.
# Exit 0 passed, 1 failed, 77 skipped with the reason (scripts/slurm-local cannot start a Slurm
# here: slurm-wlm or munge missing, or not root). Every wait has a timeout; the daemons are
# killed by scripts/slurm-local's trap, also when a timeout stops it.
set -euo pipefail
PLUMB="$(realpath "$1")"
REPO="$(realpath "$2")"

if [ -z "${SLURM_LOCAL_DIR:-}" ]; then
  # Outside: the single-process result, then this script again inside a local Slurm.
  TMP="$(mktemp -d "${TMPDIR:-/tmp}/plumb-slurm-test.XXXXXX")"
  trap 'rm -rf "$TMP"' EXIT
  cat >"$TMP/study.json" <<'EOF'
{"name": "cluster test: the paper's minute by the generalized method", "seed": 11, "runs": 4,
 "design": "grid",
 "base": {"schedule": "paper_static", "still_s": 20, "rate_hz": 100, "sensor": "typical",
          "random_truth": 1, "lat_deg": 6.67, "lon_deg": -1.57, "height_m": 250},
 "factors": [{"name": "still_s", "levels": [10, 20, 40]},
             {"name": "gyro_rw", "levels": [2e-6, 2e-5]}]}
EOF
  timeout 120 "$PLUMB" sweep "$TMP/study.json" --out "$TMP/single" --jobs 1 >/dev/null
  set +e
  TEST_TMP="$TMP" timeout -k 10 240 "$REPO/scripts/slurm-local" --timeout 60 -- "$0" "$@"
  status=$?
  set -e
  if [ $status -eq 77 ]; then echo "skipped: see the reason above"; fi
  exit $status
fi

# Inside: SLURM_CONF points at the local Slurm.
TMP="$TEST_TMP"
failed=0
check() {  # check WHAT COMMAND...: runs COMMAND, says ok or FAILED
  local what="$1"; shift
  if "$@"; then echo "ok      $what"; else echo "FAILED  $what"; failed=1; fi
}

timeout 180 "$REPO/scripts/sweep-slurm" "$TMP/study.json" --out "$TMP/slurm" --tasks 3 \
  --plumb "$PLUMB" --wait --time=5 >"$TMP/sweep.out" 2>&1 || true
cat "$TMP/sweep.out"
check "the job array of 3 shards and the merge job wrote the result" test -d "$TMP/slurm"
check "every file byte-equal to plumb sweep's in one process" diff -r "$TMP/single" "$TMP/slurm"
check "one log per array element" test -f "$TMP/slurm.shards/logs/array-2.out"

# A study plumb refuses: said before anything is submitted.
python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))
s["factors"] = [{"name": "pose", "levels": [3]}]; json.dump(s, open(sys.argv[2], "w"))' \
  "$TMP/study.json" "$TMP/bad.json"
# Runs sweep-slurm with a time limit, its output to $TMP/NAME.out and shown; its exit in $status.
sweep_slurm() {
  local name=$1 limit=$2
  shift 2
  set +e
  timeout "$limit" "$REPO/scripts/sweep-slurm" "$@" --out "$TMP/$name" --tasks 2 --wait --time=5 \
    >"$TMP/$name.out" 2>&1
  status=$?
  set -e
  cat "$TMP/$name.out"
}
sweep_slurm bad 120 "$TMP/bad.json" --plumb "$PLUMB"
check "a study plumb refuses: exit 1, nothing submitted" \
  test $status -eq 1 -a ! -e "$TMP/bad.shards" -a ! -e "$TMP/bad"
check "  with plumb's error" grep -q "nothing submitted: plumb: error: .*unknown factor 'pose'" \
  "$TMP/bad.out"

# A shard that fails on its node (plumb wrapped to fail on shard 2 of 2): the merge job is
# cancelled, no result is written, the failed element's log is shown.
cat >"$TMP/plumb-failing-shard-2" <<EOF
#!/bin/bash
for a in "\$@"; do
  if [ "\$a" = 2/2 ]; then echo "plumb: error: shard 2/2 fails on purpose (the test's wrapper)" >&2; exit 1; fi
done
exec "$PLUMB" "\$@"
EOF
chmod +x "$TMP/plumb-failing-shard-2"
sweep_slurm failed 180 "$TMP/study.json" --plumb "$TMP/plumb-failing-shard-2"
check "a shard failing on its node: exit 1, no result" test $status -eq 1 -a ! -e "$TMP/failed"
check "  the failed element's log shown, the shard named" \
  grep -q "sweep-slurm: shard 2/2 failed: plumb exited 1" "$TMP/failed.out"
check "  with plumb's error" grep -q "fails on purpose" "$TMP/failed.out"
check "  the other shard ran" test -f "$TMP/failed.shards/shard-1/points/point-00000.json"
if [ $failed -eq 0 ]; then echo "passed"; else echo "FAILED"; fi
exit $failed
