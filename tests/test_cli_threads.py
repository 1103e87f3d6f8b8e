"""The command's own process runs OpenBLAS on one thread unless the user chose (issue 41: threads that
spin-wait on 2 shared cores made ``fracid check`` of the DIC example 3 to 5 times slower)."""

import os
import subprocess
import sys

import pytest

PROBE = ("import sys, os, fracid.__main__; "
         "print('numpy' in sys.modules, os.environ.get('OPENBLAS_NUM_THREADS'), os.environ.get('MKL_NUM_THREADS'))")


def _probe(**extra):
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    env.update(extra)
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, check=True)
    return out.stdout.split()


@pytest.mark.parametrize("given, expected", [(None, "1"), ("2", "2"), ("4", "4")])
def test_openblas_threads_set_before_numpy_unless_the_user_chose(given, expected):
    extra = {} if given is None else {"OPENBLAS_NUM_THREADS": given}
    numpy_loaded, openblas, mkl = _probe(**extra)
    assert numpy_loaded == "False"  # set before OpenBLAS reads it, or it would be of no effect
    assert openblas == expected
    assert mkl == "None"  # PARDISO's MKL threads are left alone
