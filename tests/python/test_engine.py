"""The boicp package's engine and map pipeline against the boicp command line.

Run with PYTHONPATH at the folder holding the built ``boicp`` package and
BOICP at the boicp binary (ctest's ``python_engine`` sets both). The scans
are generated with ``boicp demo-data``; nothing here needs the shared data.
"""

import json
import os
import pathlib
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import boicp

BOICP = os.environ.get("BOICP")
if not BOICP:
    pytest.skip("BOICP is unset: set it to the boicp binary", allow_module_level=True)

# Keys whose values are wall times, which differ between any two runs.
TIMINGS = {"runtime_s", "loop_runtime_s", "other_pairs_runtime_s"}
# A quick search, so the tests that compare with the CLI run in seconds.
QUICK = {"config": "A", "random_samples": 4, "iterations": 4}


def run_cli(*args):
    done = subprocess.run([BOICP, *map(str, args)], capture_output=True, text=True, check=False)
    return done


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pair")
    done = run_cli("demo-data", "-o", folder, "--yaw", 40)
    assert done.returncode == 0, done.stderr
    return folder


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    folder = tmp_path_factory.mktemp("drive")
    done = run_cli("demo-data", "-o", folder, "--scans", 5)
    assert done.returncode == 0, done.stderr
    return folder


def test_read_scan_gives_the_files_points(tmp_path):
    points = np.array([[0.0, 1.5, -2.25], [1e-3, 2.0, 3.0], [4.0, 5.0, 6.5]])
    path = tmp_path / "three.xyz"
    path.write_text("".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in points))
    read = boicp.read_scan(path)
    assert read.dtype == np.float64 and read.shape == (3, 3)
    np.testing.assert_array_equal(read, points)


def test_read_scan_refuses_a_missing_file_naming_it(tmp_path):
    with pytest.raises(ValueError, match="nothing.xyz"):
        boicp.read_scan(tmp_path / "nothing.xyz")


def test_register_equals_boicp_register_json(pair):
    source = boicp.read_scan(pair / "source.xyz")
    target = boicp.read_scan(pair / "target.xyz")
    result = boicp.register(source, target, seed=7, threads=2, **QUICK)

    done = run_cli("register", "--source", pair / "source.xyz", "--target", pair / "target.xyz",
                   "--json", "-q", "--seed", 7, "--threads", 2, "--config", "A",
                   "--random-samples", 4, "--iterations", 4)
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout)
    assert without_timings(result.to_dict()) == without_timings(cli)
    np.testing.assert_array_equal(result.transform, np.array(cli["transform"]))
    assert result.confidence == cli["confidence"] and result.doubtful == cli["doubtful"]
    assert result.rmse == cli["inlier_rmse"] and result.evaluations == cli["evaluations"]
    assert result.settings["seed"] == 7


SHARED = pathlib.Path(os.environ.get("BOICP_SHARED_DATA", "../shared/data"))
# (dataset, source, target, the sensor, read_scan's and the CLI's loading options)
SHARED_PAIRS = [
    ("kitti00", "velodyne/000000.bin", "velodyne/000003.bin", "lidar", {}, []),
    ("7scenes_redkitchen", "depth/frame-000000.depth.png", "depth/frame-000030.depth.png",
     "depth", {"intrinsics_file": "camera-intrinsics.txt", "depth_scale": 1000},
     ["--intrinsics-file", "camera-intrinsics.txt", "--depth-scale", 1000]),
]


@pytest.mark.parametrize("dataset, source, target, sensor, load, load_flags", SHARED_PAIRS,
                         ids=[p[0] for p in SHARED_PAIRS])
def test_register_on_shared_scans_equals_boicp_register(dataset, source, target, sensor, load,
                                                        load_flags):
    folder = SHARED / dataset
    if not (folder / source).exists():
        pytest.skip(f"{folder} is absent (the shared data)")
    load = {k: (folder / v if k == "intrinsics_file" else v) for k, v in load.items()}
    load_flags = [folder / f if str(f).endswith(".txt") else f for f in load_flags]
    result = boicp.register(boicp.read_scan(folder / source, **load),
                            boicp.read_scan(folder / target, **load), sensor=sensor, threads=2)
    done = run_cli("register", "--source", folder / source, "--target", folder / target,
                   "--json", "-q", "--sensor", sensor, "--threads", 2, *load_flags)
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout)
    np.testing.assert_array_equal(result.transform, np.array(cli["transform"]))
    assert without_timings(result.to_dict()) == without_timings(cli)


def test_register_recovers_the_generated_motion(pair):
    truth = np.loadtxt(pair / "truth.txt")
    truth = np.vstack([truth.reshape(-1, 4)[:3], [0, 0, 0, 1]]) if truth.size == 12 else \
        truth.reshape(4, 4)
    result = boicp.register(boicp.read_scan(pair / "source.xyz"),
                            boicp.read_scan(pair / "target.xyz"))
    error = np.linalg.inv(truth) @ result.transform
    angle = np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1)))
    assert angle < 1.0 and np.linalg.norm(error[:3, 3]) < 0.1, result
    assert not result.doubtful


def test_float32_and_strided_arrays_give_the_same_answer(pair):
    source = boicp.read_scan(pair / "source.xyz")
    target = boicp.read_scan(pair / "target.xyz")
    as_float64 = boicp.register(source, target, threads=1, **QUICK)
    fortran = boicp.register(np.asfortranarray(source), target, threads=1, **QUICK)
    np.testing.assert_array_equal(as_float64.transform, fortran.transform)
    # float32 rounds the points, so only the answer's neighbourhood is the same.
    as_float32 = boicp.register(source.astype(np.float32), target.astype(np.float32), threads=1,
                                **QUICK)
    np.testing.assert_allclose(as_float32.transform, as_float64.transform, atol=1e-3)


def test_float64_rows_are_read_in_place_and_other_layouts_copied(pair):
    source = boicp.read_scan(pair / "source.xyz")
    target = boicp.read_scan(pair / "target.xyz")
    in_place = boicp._boicp._reads_in_place
    # read_scan's array holds the loader's own points, and register reads them there.
    assert not source.flags.owndata and source.base is not None
    assert in_place(source)
    with_normals = np.hstack([source, np.ones_like(source)])
    assert in_place(with_normals[:, :3])
    for copied in (np.asfortranarray(source), source[::-1], source.astype(np.float32),
                   source.astype(">f8")):
        assert not in_place(copied)
    # Viewed or copied, the engine reads the same numbers.
    reference = boicp.register(source, target, threads=1, **QUICK)
    for layout in (with_normals[:, :3], source.astype(">f8")):
        np.testing.assert_array_equal(
            boicp.register(layout, target, threads=1, **QUICK).transform, reference.transform)


def test_a_prior_is_used(pair):
    source = boicp.read_scan(pair / "source.xyz")
    target = boicp.read_scan(pair / "target.xyz")
    first = boicp.register(source, target)
    from_prior = boicp.register(source, target, prior=first.transform)
    assert from_prior.answered_by == "prior"
    np.testing.assert_allclose(from_prior.transform, first.transform, atol=1e-3)


@pytest.mark.parametrize("kwargs, message", [
    ({"voxel": -1.0}, "voxel"),
    ({"voxle": 0.1}, "unknown setting 'voxle'"),
    ({"budget": "cheap"}, "cheap"),
    ({"translation_bounds": (1.0, 2.0)}, "three numbers"),
    ({"resolution": 0.1}, "does not take 'resolution'"),
])
def test_a_bad_setting_is_a_value_error_naming_it(pair, kwargs, message):
    points = boicp.read_scan(pair / "source.xyz")
    with pytest.raises(ValueError, match=message):
        boicp.register(points, points, **kwargs)


@pytest.mark.parametrize("points, message", [
    (np.zeros((10, 2)), r"\(N, 3\)"),
    (np.zeros((10, 3), dtype=np.int64), "float64 or float32"),
    (np.array([[0.0, 0.0, np.nan]] * 10), "not finite"),
])
def test_bad_points_are_value_errors(pair, points, message):
    target = boicp.read_scan(pair / "target.xyz")
    with pytest.raises(ValueError, match=message):
        boicp.register(points, target)


def test_a_prior_that_is_not_a_motion_is_refused(pair):
    points = boicp.read_scan(pair / "source.xyz")
    with pytest.raises(ValueError, match="prior"):
        boicp.register(points, points, prior=2 * np.eye(4))


def test_the_engine_runs_without_the_gil(pair):
    source = boicp.read_scan(pair / "source.xyz")
    target = boicp.read_scan(pair / "target.xyz")
    started, finished = threading.Event(), threading.Event()
    wakeups = 0

    def run():
        started.set()
        boicp.register(source, target, budget="fixed", threads=1)  # 180 ICP runs
        finished.set()

    worker = threading.Thread(target=run)
    worker.start()
    started.wait()
    while not finished.is_set():
        # Each wakeup needs the GIL back: while the search held it, this
        # thread would wake once, then wait for the search to end.
        time.sleep(0.002)
        wakeups += 1
    worker.join()
    assert wakeups >= 10


def map_summary_without_paths(summary):
    return {k: v for k, v in without_timings(summary).items() if k != "outputs"}


def test_build_map_writes_what_boicp_map_writes(drive, tmp_path):
    events = []
    summary = boicp.build_map(drive, tmp_path / "py", threads=1, progress=events.append,
                              seed=3, **QUICK)
    done = run_cli("map", drive, "-o", tmp_path / "cli", "--threads", 1, "--json", "--seed", 3,
                   "--config", "A", "--random-samples", 4, "--iterations", 4)
    assert done.returncode == 0, done.stderr
    cli = json.loads(done.stdout.strip().splitlines()[-1])
    assert map_summary_without_paths(summary) == map_summary_without_paths(cli)
    for name in ("trajectory.kitti", "trajectory.tum", "map.bt"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert summary["outputs"]["map.bt"] == str(tmp_path / "py" / "map.bt")

    pairs = [e for e in events if e["event"] == "pair"]
    assert [(e["source"], e["target"]) for e in pairs] == [(i, i + 1) for i in range(4)]
    assert pairs[-1]["done"] == pairs[-1]["total"] == 4
    assert [e["stage"] for e in events if e["event"] == "stage"][-1] == "fusing"
    assert any(e["event"] == "fusing" for e in events)


def test_a_second_build_map_reuses_the_pairs(drive, tmp_path):
    first = boicp.build_map(drive, tmp_path, threads=1, **QUICK)
    second = boicp.build_map(drive, tmp_path, threads=1, **QUICK)
    assert first["pairs_reused"] == 0 and second["pairs_reused"] == 4


def test_an_exception_in_progress_stops_the_map_and_is_raised(drive, tmp_path):
    class Stop(Exception):
        pass

    def progress(event):
        if event["event"] == "pair":
            raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        boicp.build_map(drive, tmp_path, threads=1, progress=progress, **QUICK)
    assert not (tmp_path / "map.bt").exists()
    # The pair that finished is kept for the next run.
    assert list((tmp_path / "pairs").glob("*.json"))


def test_build_map_takes_several_drives(drive, tmp_path):
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    scans = sorted(p for p in drive.iterdir() if p.suffix == ".xyz")
    for k, scan in enumerate(scans):
        (first if k < 3 else second).joinpath(scan.name).symlink_to(scan)
    summary = boicp.build_map(first, tmp_path / "out", threads=1, more_paths=[str(second)],
                              **QUICK)
    assert [d["scans"] for d in summary["drives"]] == [3, 2]
    assert (tmp_path / "out" / "trajectory-second.kitti").read_text().count("\n") == 2


def test_build_map_names_a_bad_setting(drive, tmp_path):
    with pytest.raises(ValueError, match="unknown setting 'resolutoin'"):
        boicp.build_map(drive, tmp_path, resolutoin=0.2)
    with pytest.raises(ValueError, match="pairing"):
        boicp.build_map(drive, tmp_path, pairing="sideways")


def test_ctrl_c_stops_build_map_and_raises_keyboard_interrupt(tmp_path):
    folder = tmp_path / "long"
    assert run_cli("demo-data", "-o", folder, "--scans", 40).returncode == 0
    script = textwrap.dedent(f"""
        import boicp
        def progress(event):
            if event["event"] == "pair":
                print("pair", flush=True)
        try:
            boicp.build_map({str(folder)!r}, {str(tmp_path / "out")!r}, threads=1,
                            budget="fixed", progress=progress)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True,
                             env=os.environ)
    assert child.stdout.readline().strip() == "pair"
    child.send_signal(signal.SIGINT)
    # A hang guard, not a speed target: the stop is polled every 50 ms.
    out, _ = child.communicate(timeout=120)
    assert "interrupted" in out and child.returncode == 0
    assert not (tmp_path / "out" / "map.bt").exists()
    assert len(list((tmp_path / "out" / "pairs").glob("*.json"))) < 39
