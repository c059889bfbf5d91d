#!/usr/bin/env bash
# The URDFs a generator writes are up to date: each is written again into a
# temporary folder and must equal the committed file byte for byte.
#   generated_urdfs_test.sh            (from anywhere; needs python3-numpy)
set -uo pipefail
export PATH=/usr/bin:/bin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 "$repo/scripts/c60_model/c60_scene.py" --out-dir "$tmp" || { echo "FAIL: scripts/c60_model/c60_scene.py failed"; exit 1; }
fail=0 checked=0
for f in "$tmp"/*.urdf; do
  name=$(basename "$f")
  checked=$((checked + 1))
  if ! cmp -s "$f" "$repo/urdf/$name"; then
    echo "FAIL: urdf/$name differs from what scripts/c60_model/c60_scene.py writes now (regenerate it and commit):"
    diff "$repo/urdf/$name" "$f" | head -n 10
    fail=1
  fi
done
[ "$checked" -gt 0 ] || { echo "FAIL: the generator wrote no URDF"; exit 1; }
[ "$fail" -eq 0 ] && echo "generated URDFs: $checked up to date"
exit "$fail"
