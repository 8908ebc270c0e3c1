"""Cyclone DDS bare participant for the footprint probe: joins DOMAIN with no endpoints and idles."""
import os
import sys
import time

from cyclonedds.domain import DomainParticipant

dp = DomainParticipant(int(sys.argv[1]))
print(f"ready pid {os.getpid()}", flush=True)
time.sleep(float(sys.argv[2]) if len(sys.argv) > 2 else 3600)
