"""What the Cyclone DDS peer scripts beside it share (they run by path, so this directory is on sys.path)."""
import sys
import time
from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final, key
from cyclonedds.idl.types import int32


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def wait_match(status, what, seconds=20):
    """Waits until `status()` (a matched status getter) counts a match; exits with 2 after `seconds`."""
    deadline = time.time() + seconds
    while status().current_count == 0:
        if time.time() > deadline:
            log(f"{what}: no match")
            sys.exit(2)
        time.sleep(0.05)
    log(f"{what}: matched")


@dataclass
@final
class Beat(IdlStruct, typename="xs::Beat"):
    """The keyed type of the status and dynamic-API peers (`cyclone_status.py`, `cyclone_dynapi.py`)."""
    id: int32
    key("id")
    n: int32
