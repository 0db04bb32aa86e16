"""What the run log records of the code and its libraries, and what that must not do.

The run log is written by rank 0 alone. Whatever it calls must start nothing whose end
is collective: SLEPc initialised on rank 0 only (by importing ``slepc4py.SLEPc``) is
finalised at exit on rank 0 only, a collective call the other ranks never join, and the
MPI job hangs at exit.
"""

import subprocess
import sys

import pytest


@pytest.mark.serial
def test_library_versions_initialise_no_slepc():
    script = (
        "from mpi4py import MPI\n"
        "import sys\n"
        "from rwall_fem.provenance import library_versions\n"
        "versions = library_versions()\n"
        "print(versions['slepc'], 'slepc4py.SLEPc' in sys.modules)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    ).stdout.split()
    version, initialised = out
    assert version.count(".") == 2 and version.split(".")[0] == "3"
    assert initialised == "False"
