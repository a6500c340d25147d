"""`hox study --shard K/N` + `hox study merge` against one run, and `hox.study` through an
executor against the command line (issue #60). The locking table is the plan: its cells are
static solves, so every number of it is the same on every run but XPBD's and Newton's ms per
frame (its last two columns), which are left out of the comparisons."""

import subprocess
from concurrent.futures import ProcessPoolExecutor

import pytest

import hox
from hox.study import _rows


TIMING = "ms_per_frame_1_thread"
TIMINGS = (TIMING, "newton_ms_per_frame_1_thread")


def without_timing(name, text):
    """locking.csv without its timing columns; study.md without its tables' last two cells (ms/frame)."""
    if name.endswith(".csv"):
        return [{k: v for k, v in row.items() if k not in TIMINGS} for row in _rows(text)]
    return [line.rsplit("|", 3)[0] if line.startswith("| ") else line for line in text.splitlines()]


def run(hox_binary, *args, ok=True):
    done = subprocess.run([hox_binary, *map(str, args)], capture_output=True, text=True)
    assert (done.returncode == 0) == ok, f"hox {' '.join(map(str, args))}: exit {done.returncode}\n{done.stderr}"
    return done


@pytest.fixture(scope="module")
def unsharded(hox_binary, tmp_path_factory):
    out = tmp_path_factory.mktemp("whole")
    run(hox_binary, "study", "--quick", "--only", "locking", "--out", out)
    return out


def test_study_shard_parts_merged_equal_the_unsharded_study(hox_binary, unsharded, tmp_path):
    parts = tmp_path / "parts"
    # the parts run in any order, each on its own (a job array's tasks)
    for k in (2, 1, 3):
        run(hox_binary, "study", "--quick", "--only", "locking", "--shard", f"{k}/3", "--out", parts)
    assert sorted(p.name for p in parts.iterdir()) == [f"study-part-{k}-of-3.toml" for k in (1, 2, 3)]
    merged = tmp_path / "merged"
    run(hox_binary, "study", "merge", parts, "--out", merged)
    assert sorted(p.name for p in merged.iterdir()) == sorted(p.name for p in unsharded.iterdir()) == ["locking.csv", "study.md"]
    for name in ("locking.csv", "study.md"):
        merged_text, whole_text = (merged / name).read_text(), (unsharded / name).read_text()
        assert without_timing(name, merged_text) == without_timing(name, whole_text), name
    rows = _rows((merged / "locking.csv").read_text())
    assert len(rows) == 4 * 6, "4 Poisson ratios × P1, P2 and P3, plain and mixed"
    assert all(row[TIMINGS[1]] > 0 for row in rows), "every cell's Newton ms per frame"
    assert all(row[TIMING] > 0 for row in rows), "every cell's XPBD ms per frame, P1 mixed's node patches too"


def test_a_merge_missing_a_part_or_given_one_twice_writes_nothing(hox_binary, tmp_path):
    parts = tmp_path / "parts"
    run(hox_binary, "study", "--quick", "--only", "locking", "--shard", "1/2", "--out", parts)
    out = tmp_path / "out"
    out.mkdir()
    (out / "locking.csv").write_text("kept\n")
    failed = run(hox_binary, "study", "merge", parts, "--out", out, ok=False)
    assert "part 2/2 missing" in failed.stderr
    part = parts / "study-part-1-of-2.toml"
    failed = run(hox_binary, "study", "merge", part, part, "--out", out, ok=False)
    assert "both part 1/2" in failed.stderr
    assert (out / "locking.csv").read_text() == "kept\n", "nothing already written is lost"
    for bad, says in (("3/2", "K/N"), ("0/2", "K/N"), ("x", "K/N")):
        assert says in run(hox_binary, "study", "--quick", "--shard", bad, "--out", tmp_path / "x", ok=False).stderr
    failed = run(hox_binary, "study", "--quick", "--only", "speed", "--out", tmp_path / "x", ok=False)
    assert "speed" in failed.stderr and "accuracy, locking, solvers" in failed.stderr
    (tmp_path / "junk.toml").write_text("title = 1\n")
    failed = run(hox_binary, "study", "merge", tmp_path / "junk.toml", "--out", out, ok=False)
    assert "junk.toml" in failed.stderr and "not a study part" in failed.stderr


def test_hox_study_through_a_process_pool_equals_the_command_line(unsharded):
    pandas = pytest.importorskip("pandas")
    with ProcessPoolExecutor(max_workers=2) as pool:
        tables = hox.study(quick=True, tables=["locking"], executor=pool)
    assert list(tables) == ["locking"]
    frame = tables["locking"]
    assert isinstance(frame, pandas.DataFrame), "a DataFrame when pandas is installed"
    assert list(frame.columns) == [
        "poisson_ratio", "configuration", "formulation", "elements", "tip_z_m", "reference_tip_z_m", "reference_mesh",
        "missing_pct", *TIMINGS,
    ]
    records = [{k: v for k, v in row.items() if k not in TIMINGS} for row in frame.to_dict("records")]
    assert records == without_timing("locking.csv", (unsharded / "locking.csv").read_text())
    p1 = frame[frame.configuration == "P1 16x4x4 five"].set_index(["formulation", "poisson_ratio"]).missing_pct
    assert p1["energy", 0.499] > p1["energy", 0.35] + 10, "P1 locks as ν → 0.5"
    assert abs(p1["mixed", 0.499]) < 5, "its node patches cure it: P1 1,280 mixed within 5 % at ν = 0.499"
    p2 = frame[frame.configuration == "P2 8x2x2 five"].set_index(["formulation", "poisson_ratio"]).missing_pct
    assert p2["energy", 0.499] > 4 and abs(p2["mixed", 0.499]) < 1.5, "the mixed P2 160 is within 1.5 % at ν = 0.499"
    assert hox.study_cells(True, ["locking"]) == [f"locking ν = {nu}" for nu in (0.35, 0.45, 0.49, 0.499)]
    with pytest.raises(ValueError, match="speed"):
        hox.study_cells(True, ["speed"])


def test_a_process_pool_forked_after_a_run_does_not_hang():
    """Found running the whole suite (2026-12-01): a process pool forked after a simulation had
    started rayon's threads waited for ever in its workers (a fork copies one thread)."""
    import multiprocessing

    sim = hox.Simulation(hox.Scene.builtin("bending").with_params(element="p2", sweep="colour"))
    sim.step(2)
    cells = [hox.Cell("bending", {"element": e, "grid": (4, 1, 1)}, seconds=0.1) for e in ("p1", "p2")]
    pool = ProcessPoolExecutor(max_workers=2, mp_context=multiprocessing.get_context("fork"))
    try:
        rows = list(pool.map(hox.run_cell, cells, timeout=120))
    finally:
        # a hung worker would hold a plain shutdown for ever: the test fails instead
        for worker in list(getattr(pool, "_processes", {}).values()):
            worker.kill()
        pool.shutdown(wait=False, cancel_futures=True)
    strip = lambda rs: [{k: v for k, v in r.items() if k != "ms_per_frame"} for r in rs]
    assert strip(rows) == strip(hox.sweep(cells))
