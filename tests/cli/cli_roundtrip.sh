#!/usr/bin/env bash
# CLI round trip against a running bus: backup, change, restore, read back; a corrupted file refused.
# (The other exit codes are checked in-process by test_cli_commands.py: each launch here costs a second.)
# usage: cli_roundtrip.sh BUS_SPEC WORK_DIR   (SERVOSTUDIO may name the servostudio executable)
set -euo pipefail
bus=$1
work=$2
ss=${SERVOSTUDIO:-servostudio}
raw() { python3 -c 'import json, sys; print(json.load(sys.stdin)["raw"])'; }
exit_code() { set +e; "$@" 2> "$work/stderr.txt" > /dev/null; echo $?; set -e; }

# Backup identifies the node by itself (0x1018 -> EDS library); later calls name the device.
"$ss" backup --bus "$bus" --node 1 --out "$work/DRIVEPAR.TXT" > "$work/backup.json"
grep -q '"kind": "DRIVEPAR.TXT"' "$work/backup.json"
original=$(grep '^0x60F9,2=' "$work/DRIVEPAR.TXT" | cut -d= -f2)

changed=$("$ss" write --bus "$bus" --node 1 --device xtrapulspac 0x60F9,2 $((original + 1)) | raw)
[ "$changed" = $((original + 1)) ]

"$ss" restore --bus "$bus" --node 1 --in "$work/DRIVEPAR.TXT" > "$work/restore.json"
grep -q '"ok": true' "$work/restore.json"  # every object read back equal to the file
[ "$("$ss" read --bus "$bus" --node 1 --device xtrapulspac 0x60F9,2 | raw)" = "$original" ]

# A corrupted file exits 3 naming its line; nothing is written.
sed 's/^0x60F9,2=.*/0x60F9,2=banana/' "$work/DRIVEPAR.TXT" > "$work/bad_DRIVEPAR.TXT"
line=$(grep -n '^0x60F9,2=' "$work/bad_DRIVEPAR.TXT" | cut -d: -f1)
[ "$(exit_code "$ss" restore --bus "$bus" --node 1 --device xtrapulspac --in "$work/bad_DRIVEPAR.TXT")" -eq 3 ]
grep -q "bad_DRIVEPAR.TXT:$line:" "$work/stderr.txt"
echo "cli round trip ok"
