"""Importing ladartui shortens numba's OpenMP spin unless the user chose a wait policy."""

import os
import subprocess
import sys

import pytest


def _spin_count_after_import(**settings):
    env = {k: v for k, v in os.environ.items() if k not in ("GOMP_SPINCOUNT", "OMP_WAIT_POLICY")}
    env.update(settings)
    code = "import os, ladartui; print(os.environ.get('GOMP_SPINCOUNT'))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


@pytest.mark.parametrize(
    ("settings", "expected"),
    [
        ({}, "30000"),
        ({"GOMP_SPINCOUNT": "7"}, "7"),  # the user's own count stands
        ({"OMP_WAIT_POLICY": "ACTIVE"}, "None"),  # so does a wait policy, with libgomp's count
    ],
)
def test_spin_count(settings, expected):
    assert _spin_count_after_import(**settings) == expected
