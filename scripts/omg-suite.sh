#!/usr/bin/env bash
# The OMG DDS-RTPS interoperability suite (github.com/omg-dds/dds-rtps) against our shape_main.
#
# The suite's licence allows using it for interoperability testing but forbids redistributing it, so nothing of
# it enters this repository: point this script at your own checkout. Peers are built under target/omg/ (ignored
# by git) and the suite runs inside scripts/isolated (a loopback-only network namespace).
#
#   scripts/omg-suite.sh build SUITE_DIR [PEER..] build the peers (default all): Cyclone DDS 11.0.1 (srcC, against
#                                                ../shared/cyclonedds-11.0.1, with scripts/omg/cyclone_shim.h),
#                                                Fast DDS 2.9 (srcCxx, Debian libfastrtps-dev + fastddsgen),
#                                                Dust DDS 0.15 (srcRs/DustDDS, from crates.io) and ours
#   scripts/omg-suite.sh run SUITE_DIR PUB SUB [interoperability_report.py options...]
#                                                PUB/SUB: ours | cyclone | fastdds | dust | a path
#
# Examples: scripts/omg-suite.sh run ~/dds-rtps ours cyclone -x 2
#           scripts/omg-suite.sh run ~/dds-rtps ours ours -t Test_Deadline_3
# The JUnit report goes to target/omg/report-PUB-SUB.xml (OMG_OUT overrides target/omg, OMG_PEERS where the
# peers are); a summary line is printed at the end: passed, failed, and UNSUPPORTED_FEATURE cases.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$PWD
out=${OMG_OUT:-$repo/target/omg}   # reports and runs
peers=${OMG_PEERS:-$out}           # built peers (share one build between checkouts with OMG_PEERS)
cyclone=${CYCLONEDDS_HOME:-$repo/../shared/cyclonedds-11.0.1}

usage() { sed -n '2,17p' "$0" >&2; exit 2; }
[[ $# -ge 2 ]] || usage
cmd=$1 suite=$(cd "$2" && pwd); shift 2
[[ -f $suite/interoperability_report.py ]] || { echo "omg-suite: $suite is not a dds-rtps checkout" >&2; exit 2; }

# Cyclone's lib/ may hold its .so symlinks as small text files: rebuild them as real symlinks.
cyclone_libdir() {
  local l=$peers/cyclone/lib f t
  mkdir -p "$l"
  for f in "$cyclone"/lib/*.so*; do
    t=$(basename "$f")
    if [[ $(stat -c%s "$f") -lt 100 ]]; then ln -sfn "$(cat "$f")" "$l/$t"; else ln -sfn "$f" "$l/$t"; fi
  done
  echo "$l"
}

build_cyclone() {
  local d=$peers/cyclone src=$suite/srcC lib
  lib=$(cyclone_libdir)
  LD_LIBRARY_PATH=$lib "$cyclone/bin/idlc" -Wno-implicit-extensibility -o "$d" "$src/shape.idl"
  gcc -O2 -DCYCLONE_DDS -include "$repo/scripts/omg/cyclone_shim.h" -I"$d" -I"$src" -I"$cyclone/include" \
    -o "$d/shape_main" "$src/shape_main.c" "$d/shape.c" -L"$lib" -Wl,-rpath,"$lib" -lddsc -lm
  echo "built $d/shape_main"
}

# srcCxx targets Fast DDS 3; Debian has 2.9, whose fastddsgen names headers .h and whose reader QoS keeps the
# representation under type_consistency(). Two substitutions in a build copy bridge that.
build_fastdds() {
  local d=$peers/fastdds src=$suite/srcCxx
  mkdir -p "$d/GeneratedCode"
  fastddsgen -replace -d "$d/GeneratedCode" "$src/shape.idl" >/dev/null
  printf '#include "shape.h"\n' >"$d/GeneratedCode/shape.hpp"
  printf '#include "shapePubSubTypes.h"\n' >"$d/GeneratedCode/shapePubSubTypes.hpp"
  sed 's/dr_qos\.representation()/dr_qos.type_consistency().representation/g' "$src/shape_main.cxx" >"$d/shape_main.cxx"
  sed 's/#define RETCODE_OK DDS::RETCODE_OK/#define RETCODE_OK eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK/' \
    "$src/shape_configurator_eprosima_fast_dds.h" >"$d/shape_configurator_eprosima_fast_dds.h"
  g++ -std=c++17 -O2 -DEPROSIMA_FAST_DDS=1 -I"$d" -o "$d/shape_main" "$d/shape_main.cxx" \
    "$d/GeneratedCode/shape.cxx" "$d/GeneratedCode/shapePubSubTypes.cxx" -lfastrtps -lfastcdr -lpthread
  echo "built $d/shape_main"
}

build_dust() {
  local d=$peers/dust
  mkdir -p "$d"
  # Its build script reads the suite's IDL by a relative path: build in place, with the target dir outside.
  (cd "$suite/srcRs/DustDDS" && CARGO_TARGET_DIR=$d/target cargo build --release)
  cp "$d/target/release/dust_dds_shape_main_linux" "$d/shape_main"
  echo "built $d/shape_main"
}

peer() {
  case $1 in
    ours) echo "$repo/target/release/shape_main" ;;
    cyclone | fastdds | dust) echo "$peers/$1/shape_main" ;;
    *) echo "$1" ;;
  esac
}

case $cmd in
  build)
    mkdir -p "$peers"
    for p in "${@:-cyclone fastdds dust ours}"; do
      for q in $p; do
        case $q in
          cyclone) build_cyclone ;; fastdds) build_fastdds ;; dust) build_dust ;;
          ours) cargo build --release -p dds-examples --bin shape_main ;;
          *) usage ;;
        esac
      done
    done
    ;;
  run)
    [[ $# -ge 2 ]] || usage
    pub=$(peer "$1") sub=$(peer "$2") name="$(basename "$1")-$(basename "$2")"; shift 2
    for p in "$pub" "$sub"; do [[ -x $p ]] || { echo "omg-suite: $p missing (run build first)" >&2; exit 2; }; done
    mkdir -p "$out/run-$name"
    # The harness writes its report relative to the working directory and imports its suite from SUITE_DIR.
    (cd "$out/run-$name" && "$repo/scripts/isolated" python3 "$suite/interoperability_report.py" \
      -P "$pub" -S "$sub" -o "$out/report-$name.xml" "$@") | tee "$out/run-$name.log"
    python3 - "$out/report-$name.xml" <<'PY'
import sys, xml.etree.ElementTree as ET
root = ET.parse(sys.argv[1]).getroot()
cases = root.iter("testcase")
passed = failed = unsupported = 0
fails = []
for c in cases:
    f = c.find("failure"); e = c.find("error"); s = c.find("skipped")
    text = " ".join((x.get("message") or "") + (x.text or "") for x in (f, e, s) if x is not None)
    if "UNSUPPORTED_FEATURE" in text:
        unsupported += 1
    elif f is not None or e is not None:
        failed += 1; fails.append(c.get("name"))
    else:
        passed += 1
print(f"summary: {passed} passed, {failed} failed, {unsupported} unsupported of {passed+failed+unsupported}")
for n in fails:
    print(f"  failed: {n}")
PY
    ;;
  *) usage ;;
esac
