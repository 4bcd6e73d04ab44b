"""The FEM tools run with tiny options (benchmark without the cold run, refinement study n <= 2)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_bench_fem_smoke():
    out = subprocess.run([sys.executable, str(ROOT / "tools" / "bench_fem.py"), "--repeats", "1", "--tile", "1",
                          "--no-cold"], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "## FEM assembly and eigen solve" in out.stdout
    assert "elements/s" in out.stdout


def test_fem_convergence_study_runs():
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import fem_convergence
    finally:
        sys.path.pop(0)
    rows = fem_convergence.study("great_belt", n_max=2, n_modes=10)
    assert [r["n"] for r in rows] == [1, 2]
    assert 0.0 <= rows[0]["change"] < 0.05   # 1 -> 2 elements per panel moves the first 10 modes < 5 %
