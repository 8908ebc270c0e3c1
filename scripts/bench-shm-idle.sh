#!/bin/bash
# Run inside scripts/isolated after building the release example dcps_shm_throughput (feature shm).
# CPU of an idle participant with shared memory on, over 10 s: utime+stime ticks and context switches.
for mode in event poll; do
  if [ $mode = poll ]; then export DDS_SHM_WAKE=poll; else unset DDS_SHM_WAKE; fi
  target/release/examples/dcps_shm_throughput sub 150 shm 1000 > /dev/null 2>&1 &
  pid=$!
  sleep 2
  a=$(awk '{print $14+$15}' /proc/$pid/stat); ca=$(cat /proc/$pid/task/*/status | awk '/voluntary_ctxt_switches/ && !/non/ {s+=$2} END {print s}')
  sleep 10
  b=$(awk '{print $14+$15}' /proc/$pid/stat); cb=$(cat /proc/$pid/task/*/status | awk '/voluntary_ctxt_switches/ && !/non/ {s+=$2} END {print s}')
  kill $pid; wait $pid 2>/dev/null
  echo "$mode: cpu $((b-a)) ticks (1/100 s) in 10 s, voluntary context switches $((cb-ca))"
done
