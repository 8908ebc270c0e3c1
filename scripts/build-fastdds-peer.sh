#!/usr/bin/env bash
# Builds the Fast DDS 2.9 shape peer (tests/peers/fastdds) into target/peers/fastdds_shape_main.
# Needs g++ and the Debian libfastrtps-dev / libfastcdr-dev packages. Uses cmake when present,
# otherwise calls g++ directly (the peer is three files). Rebuilds only when a source is newer.
set -euo pipefail
cd "$(dirname "$0")/.."
src=tests/peers/fastdds
out=target/peers
bin=$out/fastdds_shape_main
mkdir -p "$out"

if [[ -x $bin ]] && [[ -z $(find "$src" -newer "$bin" -type f) ]]; then
  echo "$bin is up to date"
  exit 0
fi

if [[ ! -f /usr/include/fastdds/dds/domain/DomainParticipant.hpp ]]; then
  echo "build-fastdds-peer: Fast DDS headers not found (apt-get install libfastrtps-dev)" >&2
  exit 2
fi

if command -v cmake >/dev/null 2>&1; then
  cmake -S "$src" -B "$out/fastdds-build" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$out/fastdds-build" -j2
  cp "$out/fastdds-build/fastdds_shape_main" "$bin"
else
  g++ -std=c++17 -O2 -Wall -Wextra -o "$bin" "$src/shape_main.cpp" "$src/shape_type.cpp" \
    -lfastrtps -lfastcdr -lpthread
fi
echo "built $bin"
