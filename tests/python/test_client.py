"""boicp.client against a real boicpd on loopback.

Run with PYTHONPATH at the folder holding the ``boicp`` package (the
generated ``boicp/v1`` stubs and ``boicp/client.py``) and BOICPD at the
daemon binary; ctest's ``python_client`` sets both. Each daemon listens on
127.0.0.1:0 in a temporary data directory, as tests/server's DaemonProcess
starts it, and is stopped after its tests (SIGTERM, then SIGKILL).
"""

import contextlib
import hashlib
import math
import os
import pathlib
import random
import re
import shutil
import sqlite3
import struct
import subprocess
import sys
import threading
import time
import types

import pytest

grpc = pytest.importorskip("grpc", reason="python3-grpcio is not installed")
BOICPD = os.environ.get("BOICPD")
if not BOICPD:
    pytest.skip("BOICPD is unset: set it to the boicpd binary", allow_module_level=True)

# Imported after the skips above, which they would turn into errors.
from boicp.client import (  # noqa: E402
    Client, DaemonError, DaemonUnreachable, ServingStatus, TlsOptions, Unauthenticated)
from boicp.v1 import map_builder_pb2 as pb  # noqa: E402

TOKEN = "s3cret-token"
LISTENING = re.compile(r"listening on (\S+):(\d+)")
SHIFT_X = 0.5  # metres the sensor moves between the two generated scans
WATCH_LIMIT_S = 60.0


class Daemon:
    """A boicpd process on a free loopback port, its log in ``directory``."""

    def __init__(self, directory, *args):
        self.log_path = directory / "boicpd.log"
        self.data_dir = directory / "data"
        command = [BOICPD, "--listen", "127.0.0.1:0", "--data-dir", str(self.data_dir),
                   "--workers", "2", *map(str, args)]
        with open(self.log_path, "wb") as log:
            self.process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
        try:
            self.address = self._wait_until_listening()
        except BaseException:
            self.stop()
            raise

    def _wait_until_listening(self):
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            match = LISTENING.search(self.log())
            if match:
                return f"127.0.0.1:{match.group(2)}"
            if self.process.poll() is not None:
                raise RuntimeError("boicpd exited before listening:\n" + self.log())
            time.sleep(0.02)
        raise RuntimeError("boicpd did not listen within 60 s:\n" + self.log())

    def log(self):
        return self.log_path.read_text(errors="replace")

    def stop(self):
        """SIGTERM (the daemon drains), SIGKILL when it has not exited in 10 s."""
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


@contextlib.contextmanager
def running_daemon(directory, *args):
    daemon = Daemon(directory, *args)
    try:
        yield daemon
    finally:
        daemon.stop()
        # pytest shows a test's captured output only when it failed.
        print("---- boicpd log (tail) ----\n" + "\n".join(daemon.log().splitlines()[-40:]))


@pytest.fixture(scope="module")
def daemon(tmp_path_factory):
    with running_daemon(tmp_path_factory.mktemp("daemon")) as d:
        yield d


@pytest.fixture
def start_daemon(tmp_path):
    """Starts a daemon of its own with extra flags; stopped after the test."""
    with contextlib.ExitStack() as stack:
        yield lambda *args: stack.enter_context(running_daemon(tmp_path, *args))


def street_scan(sensor_x, seed, n=3000):
    """KITTI .bin bytes of a sensor at (sensor_x, 0, 0), 1.7 m above a ground
    plane, between a wall along x at y = 6 and a wall along y at x = 12:
    every axis is pinned by one surface, so the shift is observable."""
    rng = random.Random(seed)
    rows = []
    for _ in range(n):
        pick = rng.random()
        if pick < 0.5:
            x, y, z = rng.uniform(-15, 15), rng.uniform(-15, 15), -1.7
        elif pick < 0.75:
            x, y, z = rng.uniform(-15, 15), 6.0, rng.uniform(-1.7, 2.0)
        else:
            x, y, z = 12.0, rng.uniform(-15, 6), rng.uniform(-1.7, 2.0)
        noise = [rng.gauss(0.0, 0.01) for _ in range(3)]
        rows.append(struct.pack("<4f", x - sensor_x + noise[0], y + noise[1], z + noise[2], 0.0))
    return b"".join(rows)


@pytest.fixture(scope="module")
def scan_folder(tmp_path_factory):
    """A KITTI-layout folder (velodyne/*.bin) of two scans SHIFT_X apart."""
    folder = tmp_path_factory.mktemp("drive")
    (folder / "velodyne").mkdir()
    for index in range(2):
        (folder / "velodyne" / f"{index:06d}.bin").write_bytes(street_scan(index * SHIFT_X, index))
    return folder


def quick_batch(num_scans, seed):
    """tests/server's QuickBatch: preset A cut to 4 + 4 evaluations, ground-vehicle bounds."""
    request = pb.SubmitBatchRequest()
    request.pairing.mode = pb.PairingPolicy.MODE_CONSECUTIVE
    config = request.config
    config.preset, config.random_samples, config.iterations, config.seed = "A", 4, 4, seed
    config.rotation_bounds.x, config.rotation_bounds.y, config.rotation_bounds.z = 0.2, 0.2, math.pi
    request.map.resolution, request.map.max_range = 0.3, 30.0
    for index in range(num_scans):
        request.scan_context.add().timestamp = float(index)
    return request


def fake_planner(calls):
    """A stand-in for boicp._boicp with plan_submission's contract: the
    batch without scan ids, and each scan's path and upload metadata."""

    def plan_submission(folder, settings):
        calls.append((folder, dict(settings)))
        paths = sorted(str(p) for p in (pathlib.Path(folder) / "velodyne").glob("*.bin"))
        request = quick_batch(len(paths), settings.get("seed", 3))
        request.label = folder
        scans = [{"path": path,
                  "metadata": pb.ScanMetadata(format=pb.SCAN_FORMAT_KITTI_BIN,
                                              timestamp=float(index)).SerializeToString()}
                 for index, path in enumerate(paths)]
        return {"request": request.SerializeToString(), "scans": scans,
                "read": lambda index: pathlib.Path(paths[index]).read_bytes(),
                "description": f"{len(paths)} scans (fake plan)"}

    module = types.ModuleType("boicp._boicp")
    module.plan_submission = plan_submission
    return module


def watch_to_end(client, job_id):
    """Every event of the job; a stuck watch is cut after WATCH_LIMIT_S."""
    watchdog = threading.Timer(WATCH_LIMIT_S, client.close)
    watchdog.start()
    try:
        return list(client.watch(job_id))
    finally:
        watchdog.cancel()


@pytest.fixture(scope="module")
def finished_job(daemon, scan_folder):
    """A job submitted through the fake plan and watched to its end."""
    calls, progress = [], []
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(sys.modules, "boicp._boicp", fake_planner(calls))
        with Client(daemon.address) as c:
            job_id = c.submit(scan_folder, label="pyclient", progress=lambda *p: progress.append(p),
                              seed=5, config="A")
            events = watch_to_end(c, job_id)
    return types.SimpleNamespace(job_id=job_id, events=events, calls=calls, progress=progress)


def test_health_is_serving(daemon):
    with Client(daemon.address) as c:
        assert c.health() == "SERVING"
        assert c.health() is ServingStatus.SERVING


def test_the_same_file_twice_is_uploaded_once(daemon, tmp_path):
    path = tmp_path / "cloud.xyz"
    path.write_text("".join(f"{i} {i % 7} {i % 3}\n" for i in range(200)))
    metadata = pb.ScanMetadata(format=pb.SCAN_FORMAT_XYZ)
    with Client(daemon.address) as c:
        first = c.upload_scan(str(path), metadata)
        second = c.upload_scan(str(path), metadata.SerializeToString())
        progress = []
        ids = c.upload_scans([str(path)] * 2, [metadata] * 2, lambda *p: progress.append(p))
    assert first.scan_id == hashlib.sha256(path.read_bytes()).hexdigest()
    assert (first.already_present, first.num_points) == (False, 200)
    assert second.scan_id == first.scan_id
    assert second.already_present
    assert ids == [first.scan_id] * 2
    assert progress == [(1, 2, 0), (2, 2, 0)], "nothing sent for bytes the daemon holds"


def test_a_corrupted_copy_on_the_daemon_is_replaced(daemon, tmp_path):
    path = tmp_path / "cloud.xyz"
    path.write_text("".join(f"{i % 11} {i} {i % 5}\n" for i in range(100)))
    metadata = pb.ScanMetadata(format=pb.SCAN_FORMAT_XYZ)
    with Client(daemon.address) as c:
        scan_id = c.upload_scan(str(path), metadata).scan_id
        stored = daemon.data_dir / "scans" / scan_id[:2] / scan_id
        stored.write_bytes(stored.read_bytes().replace(b"\n", b" ", 1))
        # FindScans still lists it: the metadata-only upload meets DATA_LOSS,
        # and the client sends the bytes after all.
        again = c.upload_scan(str(path), metadata)
    assert again.scan_id == scan_id
    assert not again.already_present, "the bytes were sent again"
    assert stored.with_name(scan_id + ".corrupt").exists(), "the daemon set its copy aside"
    assert stored.read_bytes() == path.read_bytes()


def test_submit_uploads_the_plan_and_queues_one_batch(finished_job, scan_folder):
    assert finished_job.calls == [(str(scan_folder), {"seed": 5, "config": "A"})]
    total = sum(p.stat().st_size for p in (scan_folder / "velodyne").iterdir())
    assert finished_job.progress[-1] == (2, 2, total)
    assert finished_job.events[0].job.label == "pyclient"
    assert finished_job.events[0].job.num_scans == 2


def test_watch_follows_the_job_until_it_succeeds(finished_job, daemon):
    last = finished_job.events[-1].job
    assert last.state == pb.JOB_STATE_SUCCEEDED, f"{last}\n{daemon.log()}"
    assert any(event.HasField("pair") for event in finished_job.events)
    assert all(e.job.state != pb.JOB_STATE_SUCCEEDED for e in finished_job.events[:-1])


def test_results_hold_one_pair_per_consecutive_scans_and_every_pose(finished_job, daemon):
    with Client(daemon.address) as c:
        results = c.results(finished_job.job_id, page_size=1)  # two pages of poses
    assert [(p.source, p.target) for p in results.pairs] == [(0, 1)]
    assert [pose.index for pose in results.trajectory] == [0, 1]
    # T_target_source of a sensor moved +SHIFT_X: the source's points land
    # SHIFT_X behind in the target's frame.
    transform = results.pairs[0].transform.m
    assert transform[3] == pytest.approx(-SHIFT_X, abs=0.15)
    assert results.trajectory[1].pose.m[3] == pytest.approx(SHIFT_X, abs=0.15)


def test_export_writes_complete_files(finished_job, daemon, tmp_path):
    with Client(daemon.address) as c:
        tum = c.export(finished_job.job_id, "tum", str(tmp_path / "trajectory.tum"))
        bt = c.export(finished_job.job_id, pb.EXPORT_FORMAT_OCTOMAP_BT, str(tmp_path / "map.bt"))
    assert len(open(tum).read().splitlines()) == 2
    assert open(bt, "rb").read().startswith(b"# Octomap OcTree binary file")
    assert sorted(os.listdir(tmp_path)) == ["map.bt", "trajectory.tum"], "no .part left"


def test_export_error_leaves_no_file(daemon, tmp_path):
    target = tmp_path / "map.bt"
    with Client(daemon.address) as c, pytest.raises(DaemonError) as error:
        c.export("job-missing", "bt", str(target))
    assert error.value.code == grpc.StatusCode.NOT_FOUND
    assert os.listdir(tmp_path) == []


def test_cancel_of_a_finished_job_changes_nothing(finished_job, daemon):
    # The daemon answers OK with the job as it is (job_manager's Cancel).
    with Client(daemon.address) as c:
        job = c.cancel(finished_job.job_id)
    assert job.state == pb.JOB_STATE_SUCCEEDED
    assert not job.cancel_requested


def test_an_unknown_job_is_not_found(daemon):
    with Client(daemon.address) as c, pytest.raises(DaemonError) as error:
        c.cancel("job-does-not-exist")
    assert error.value.code == grpc.StatusCode.NOT_FOUND
    assert "job-does-not-exist" in error.value.message
    assert str(error.value).startswith("CancelJob: ")


def test_a_second_submit_sends_no_bytes_and_delete_frees_the_job(finished_job, daemon,
                                                                 scan_folder, monkeypatch):
    monkeypatch.setitem(sys.modules, "boicp._boicp", fake_planner([]))
    progress = []
    with Client(daemon.address) as c:
        job_id = c.submit(scan_folder, progress=lambda *p: progress.append(p))
        assert watch_to_end(c, job_id)[-1].job.state == pb.JOB_STATE_SUCCEEDED
        assert progress[-1] == (2, 2, 0)
        assert job_id in [job.job_id for job in c.list_jobs(limit=0)]
        assert c.delete(job_id).bytes_freed > 0
        with pytest.raises(DaemonError) as error:
            c.get_job(job_id)
    assert error.value.code == grpc.StatusCode.NOT_FOUND


def test_a_token_daemon_refuses_calls_without_the_token(start_daemon, tmp_path):
    token_file = tmp_path / "token"
    token_file.write_text(f"  {TOKEN}\n")
    daemon = start_daemon("--auth-token-file", token_file)
    with Client(daemon.address) as anonymous, pytest.raises(Unauthenticated) as error:
        anonymous.list_jobs()
    assert error.value.code == grpc.StatusCode.UNAUTHENTICATED
    assert "requires a token" in str(error.value)
    with Client(daemon.address, "wrong", insecure=True) as wrong, pytest.raises(Unauthenticated):
        wrong.get_job("job-1")
    with Client(daemon.address, token_file=str(token_file), insecure=True) as right:
        assert right.list_jobs() == []
    with Client(daemon.address) as probe:
        assert probe.health() == "SERVING", "health stays open for probes"


def test_a_token_over_tls(start_daemon, tmp_path):
    if shutil.which("openssl") is None:
        pytest.skip("openssl is not available")
    key, cert = tmp_path / "key.pem", tmp_path / "cert.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1",
                    "-subj", "/CN=localhost", "-addext",
                    "subjectAltName=DNS:localhost,IP:127.0.0.1", "-keyout", str(key),
                    "-out", str(cert)], check=True, capture_output=True)
    (tmp_path / "token").write_text(TOKEN)
    daemon = start_daemon("--tls-cert", cert, "--tls-key", key,
                          "--auth-token-file", tmp_path / "token")
    with Client(daemon.address, TOKEN, TlsOptions(str(cert))) as right:
        assert right.list_jobs() == []
    with Client(daemon.address, tls={"ca_file": str(cert)}) as anonymous:
        with pytest.raises(Unauthenticated):
            anonymous.list_jobs()
    with Client(daemon.address) as plaintext, pytest.raises(DaemonUnreachable):
        plaintext.list_jobs()


def test_a_token_without_tls_is_refused_before_any_call():
    with pytest.raises(ValueError, match="the token would cross the network in plaintext"):
        Client("127.0.0.1:1", token=TOKEN)


@pytest.mark.parametrize("kwargs, message", [
    ({"token": " \n"}, "token: empty"),
    ({"token": TOKEN, "token_file": "t", "insecure": True}, "give one, not both"),
    ({"tls": TlsOptions("ca.pem", cert_file="c.pem")}, "cert_file and key_file go together"),
    ({"tls": TlsOptions(None, "c.pem", "k.pem")}, "cert_file needs ca_file"),
    ({"tls": {"ca_file": "/nonexistent/ca.pem"}}, "tls ca_file /nonexistent/ca.pem: cannot read"),
    ({"tls": {"ca": "ca.pem"}}, "tls: "),
])
def test_bad_connection_options_are_value_errors(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        Client("127.0.0.1:1", **kwargs)


def test_an_empty_token_file_is_refused(tmp_path):
    (tmp_path / "token").write_text("\n")
    with pytest.raises(ValueError, match="token_file .*: empty"):
        Client("127.0.0.1:1", token_file=str(tmp_path / "token"), insecure=True)


def test_an_unknown_export_format_is_a_value_error(tmp_path):
    with Client("127.0.0.1:1") as c, pytest.raises(ValueError, match="unknown 'png'"):
        c.export("job-1", "png", str(tmp_path / "x"))


def test_an_unreachable_daemon_says_so():
    with Client("127.0.0.1:1") as c, pytest.raises(DaemonUnreachable, match="cannot reach"):
        c.get_job("job-1")


@pytest.mark.parametrize("listed", [False, True], ids=["folder", "file-list"])
def test_submit_with_the_real_plan(daemon, scan_folder, listed):
    pytest.importorskip("boicp._boicp", reason="boicp._boicp is not built")
    scans = sorted((scan_folder / "velodyne").glob("*.bin")) if listed else scan_folder
    with Client(daemon.address) as c:
        job_id = c.submit(scans, config="A", random_samples=4, iterations=4, seed=3,
                          resolution=0.3)
        events = watch_to_end(c, job_id)
        assert events[-1].job.state == pb.JOB_STATE_SUCCEEDED, daemon.log()
        results = c.results(job_id)
    assert events[-1].job.label == str(scan_folder / "velodyne" if listed else scan_folder)
    assert [(p.source, p.target) for p in results.pairs] == [(0, 1)]
    assert len(results.trajectory) == 2
    assert results.pairs[0].transform.m[3] == pytest.approx(-SHIFT_X, abs=0.05)


class Cdr:
    """Little-endian CDR as ROS 2 serialises a message: the encapsulation
    header, then each primitive aligned to its size from after the header."""

    def __init__(self):
        self.data = bytearray(b"\x00\x01\x00\x00")

    def primitive(self, fmt, value):
        size = struct.calcsize(fmt)
        self.data += bytes(-(len(self.data) - 4) % size)
        self.data += struct.pack("<" + fmt, value)

    def string(self, text):
        self.primitive("I", len(text) + 1)
        self.data += text.encode() + b"\x00"


def point_cloud2(kitti_bin, stamp_s):
    """sensor_msgs/msg/PointCloud2 of KITTI .bin points (x, y, z, intensity as float32)."""
    message = Cdr()
    message.primitive("i", stamp_s)
    message.primitive("I", 0)
    message.string("velodyne")
    message.primitive("I", 1)  # height
    message.primitive("I", len(kitti_bin) // 16)  # width
    message.primitive("I", 4)
    for offset, name in enumerate(["x", "y", "z", "intensity"]):
        message.string(name)
        message.primitive("I", 4 * offset)
        message.primitive("B", 7)  # FLOAT32
        message.primitive("I", 1)
    message.primitive("B", 0)  # is_bigendian
    message.primitive("I", 16)  # point_step
    message.primitive("I", len(kitti_bin))  # row_step
    message.primitive("I", len(kitti_bin))
    message.data += kitti_bin
    message.primitive("B", 1)  # is_dense
    return bytes(message.data)


def ros2_bag(path, clouds):
    """A rosbag2 sqlite3 file with one PointCloud2 topic, a message a second."""
    with contextlib.closing(sqlite3.connect(path)) as db, db:
        db.executescript(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
            " timestamp INTEGER NOT NULL, data BLOB NOT NULL);")
        db.execute("INSERT INTO topics VALUES (1, '/points', 'sensor_msgs/msg/PointCloud2',"
                   " 'cdr', '')")
        for index, cloud in enumerate(clouds):
            db.execute("INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?, ?)",
                       ((index + 1) * 10**9, point_cloud2(cloud, index + 1)))
    return path


def test_submit_uploads_a_bags_scans_and_maps_them(daemon, tmp_path):
    pytest.importorskip("boicp._boicp", reason="boicp._boicp is not built")
    bag = ros2_bag(tmp_path / "drive.db3", [street_scan(i * SHIFT_X, i) for i in range(2)])
    progress = []
    with Client(daemon.address) as c:
        job_id = c.submit(bag, config="A", random_samples=4, iterations=4, seed=3, resolution=0.3,
                          progress=lambda *p: progress.append(p))
        events = watch_to_end(c, job_id)
        assert events[-1].job.state == pb.JOB_STATE_SUCCEEDED, daemon.log()
        results = c.results(job_id)
    assert [p[:2] for p in progress] == [(1, 2), (2, 2)]
    assert [(p.source, p.target) for p in results.pairs] == [(0, 1)]
    assert results.pairs[0].transform.m[3] == pytest.approx(-SHIFT_X, abs=0.05)


def test_submit_names_a_bad_setting_before_any_upload(daemon, scan_folder):
    pytest.importorskip("boicp._boicp", reason="boicp._boicp is not built")
    with Client(daemon.address) as c:
        with pytest.raises(ValueError, match="unknown setting 'voxle'"):
            c.submit(scan_folder, voxle=0.1)
        with pytest.raises(ValueError, match="does not take 'icp_iterations'"):
            c.submit(scan_folder, icp_iterations=3)
