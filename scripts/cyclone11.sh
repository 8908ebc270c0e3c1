# Sourced by the benchmark scripts: cyclone11_ddsperf ROOT DIR writes DIR/cy11, a wrapper that runs Cyclone
# 11's ddsperf from ROOT (../shared/cyclonedds-11.0.1) and prints its path. The shared/ copy carries its library
# links as small text files naming their targets: real links go into DIR/cyclib, for LD_LIBRARY_PATH.
cyclone11_ddsperf() {
  local root=$1 dir=$2 lib=$2/cyclib
  mkdir -p "$lib"
  for f in "$root"/lib/*.so*; do
    local target=$f
    while [[ $(stat -c %s "$target") -lt 64 ]]; do target=$root/lib/$(cat "$target"); done
    ln -sf "$(realpath "$target")" "$lib/$(basename "$f")"
  done
  printf '#!/bin/sh\nLD_LIBRARY_PATH=%s exec %s "$@"\n' "$lib" "$(realpath "$root/bin/ddsperf")" >"$dir/cy11"
  chmod +x "$dir/cy11"
  echo "$dir/cy11"
}
