#!/usr/bin/env bash
# Which corpus files does Debian's Cyclone idlc (0.10.2) accept? Prints a per-folder table.
# Cyclone's idlc can exhaust memory on one corpus file: every run gets `ulimit -v` and `timeout`.
# Usage: idlc/benches/cyclone-accepts.sh [CORPUS_DIR] [LIST_FILE]
#   LIST_FILE (optional) receives one line per file: "<rel path>\t<rc>".
set -u
corpus=${1:-$(dirname "$0")/../../../shared/idl-corpus}
list=${2:-/dev/null}
cyclone=${CYCLONE_IDLC:-/usr/bin/idlc}
[ -x "$cyclone" ] || { echo "SKIP: $cyclone not installed"; exit 0; }
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
: > "$list"
echo "| folder | files | Cyclone idlc accepts |"
echo "|---|---:|---:|"
for dir in "$corpus"/*/; do
  folder=$(basename "$dir")
  inc=()
  [ "$folder" = rti-ros-data-types ] && inc=(-I "$dir")
  n=0; ok=0
  while IFS= read -r f; do
    n=$((n+1))
    # 2 GiB of address space and 20 s are far more than any accepted file needs.
    ( ulimit -v 2097152; cd "$out" && timeout 20 "$cyclone" -o "$out" "${inc[@]}" "$f" ) >/dev/null 2>&1
    rc=$?
    [ $rc -eq 0 ] && ok=$((ok+1))
    printf '%s\t%s\n' "${f#"$corpus"/}" "$rc" >> "$list"
  done < <(find "$dir" -name '*.idl' | sort)
  echo "| $folder | $n | $ok |"
done
