"""The benchmark script keeps working (tiny size; its numbers are not asserted here)."""

import csv
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))

import bench_geodesics  # noqa: E402


def test_geodesic_benchmark_runs_and_writes_csv(tmp_path):
    out = tmp_path / "geodesics.csv"
    rows = bench_geodesics.main(["--size", "6", "--rk4-subset", "9", "--out", str(tmp_path)])
    steppers = {r["stepper"] for r in rows}
    assert steppers == {"dopri5", "dop853", "rk4"}
    with out.open() as f:
        assert len(list(csv.DictReader(f))) == len(rows)
    for r in rows:
        assert r["geodesics_per_s_per_core"] > 0 and r["status_mismatch"] == 0
