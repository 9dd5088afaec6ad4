#!/usr/bin/env bash
# Every key a TOML reader accepts is documented in its page (the scene reader in docs/scenes.md, the
# study reader in docs/studies.md). The keys are the string
# literals of each `allow_only(TABLE, {…})` list in the reader (the lists its unknown-key error
# checks against, so they are every key it reads); a key is documented when one of the page's
# ```toml examples has a line `KEY = …` (commented out or not, e.g. the alternatives of a
# table) or a table header naming it ([KEY], [[KEY]], [models.KEY], [tools.KEY]). A key name
# shared by two tables (springs' and a sphere's grasp_radius) counts once.
# Usage: scene_keys_documented.sh READER.cpp DOC.md
set -euo pipefail
reader=$1
doc=$2
keys=$(tr '\n' ' ' < "$reader" | grep -oE 'allow_only\([^,()]*, *\{[^}]*\}' | grep -oE '"[A-Za-z0-9_]+"' | tr -d '"' |
       sort -u || true)
if [[ -z $keys ]]; then
  echo "$reader: no allow_only(TABLE, {…}) key list found (has the reader changed how it lists its keys?)" >&2
  exit 1
fi
examples=$(awk '/^```toml/ { on = 1; next } /^```/ { on = 0 } on' "$doc")
count=0
missing=0
for k in $keys; do
  count=$((count + 1))
  if grep -qE "(^|[[:space:]#:])$k[[:space:]]*=|^\[\[?([A-Za-z_]+\.)*$k(\.[A-Za-z_]+)*\]\]?" <<< "$examples"; then
    continue
  fi
  echo "$doc: the key '$k', which $reader accepts, is not documented (no '$k = …' line or [$k] table in its TOML examples)" >&2
  missing=$((missing + 1))
done
echo "$count keys accepted by $reader, $((count - missing)) documented in $doc"
[[ $missing -eq 0 ]]
