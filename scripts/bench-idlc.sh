#!/usr/bin/env bash
# idlc speed on a real include-heavy data model, beside Cyclone DDS's idlc, in one run (a benchmark, not a test).
#
#   scripts/bench-idlc.sh [DIR]        DIR defaults to ../shared/idl-corpus/rti-ros-data-types
#
# Ours: one process, every file on one command line, `--check` (the whole front end and the Rust back end,
# nothing written), best of ROUNDS (default 5). Set IDLC_BEFORE=path/to/older/idlc to time another build the
# same way. Cyclone's idlc takes one file per call and has no check mode: it is timed generating C into a
# temporary directory, one process per file. CPU time (user+sys) is reported beside wall time, since this
# 2-core machine is often loaded.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-../shared/idl-corpus/rti-ros-data-types}
rounds=${ROUNDS:-5}
[[ -d $dir ]] || { echo "SKIP: $dir not found"; exit 0; }
dir=$(cd "$dir" && pwd)
mapfile -t files < <(find "$dir" -name '*.idl' | sort)
n=${#files[@]}
cargo build -q --release -p idlc
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Cyclone's shared/ copy carries its library links as small text files naming their targets: make real links.
cyclone_env() {
  local root=$1 lib=$tmp/cyclib-$2
  mkdir -p "$lib"
  for f in "$root"/lib/*.so*; do
    local target=$f
    while [[ $(stat -c %s "$target") -lt 64 ]]; do target=$root/lib/$(cat "$target"); done
    ln -sf "$target" "$lib/$(basename "$f")"
  done
  echo "$lib"
}

# best_of LABEL CMD...: best wall and CPU seconds of ROUNDS runs of CMD.
best_of() {
  local label=$1; shift
  local best_wall=999999 best_cpu=999999
  for _ in $(seq "$rounds"); do
    /usr/bin/time -f '%e %U %S' -o "$tmp/time" "$@" >/dev/null 2>&1 || true
    # (GNU time puts "Command exited with non-zero status N" first when a file has errors.)
    read -r wall user sys < <(tail -n 1 "$tmp/time")
    cpu=$(echo "$user + $sys" | bc)
    best_wall=$(echo "if ($wall < $best_wall) $wall else $best_wall" | bc)
    best_cpu=$(echo "if ($cpu < $best_cpu) $cpu else $best_cpu" | bc)
  done
  printf '%-34s %8.3f s wall %8.0f files/s   %8.3f s CPU %8.0f files/s\n' "$label" "$best_wall" \
    "$(echo "$n / ($best_wall + 0.0005)" | bc -l)" "$best_cpu" "$(echo "$n / ($best_cpu + 0.0005)" | bc -l)"
}

per_file() { # per_file IDLC ARGS...: one process per input file
  local bin=$1; shift
  for f in "${files[@]}"; do "$bin" "$@" "$f" || true; done
}

echo "$n files in $dir, best of $rounds"
best_of "ours (target/release/idlc)" target/release/idlc --check -I "$dir" "${files[@]}"
if [[ -n ${IDLC_BEFORE:-} ]]; then
  best_of "ours, before ($IDLC_BEFORE)" "$IDLC_BEFORE" --check -I "$dir" "${files[@]}"
fi
c11=../shared/cyclonedds-11.0.1
if [[ -x $c11/bin/idlc ]]; then
  lib=$(cyclone_env "$c11" 11)
  mkdir -p "$tmp/c11"
  best_of "Cyclone 11.0.1 idlc (per file)" env LD_LIBRARY_PATH="$lib" bash -c \
    "$(declare -p files); $(declare -f per_file); cd $tmp/c11 && per_file $PWD/$c11/bin/idlc -I $dir"
fi
if [[ -x /usr/bin/idlc ]]; then
  mkdir -p "$tmp/c10"
  best_of "Cyclone 0.10.2 idlc (per file)" bash -c \
    "$(declare -p files); $(declare -f per_file); cd $tmp/c10 && per_file /usr/bin/idlc -I $dir"
fi
