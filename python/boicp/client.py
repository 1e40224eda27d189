"""A Python client of boicpd, the BO-ICP map-building daemon.

It speaks the daemon's gRPC API (``proto/boicp/v1/map_builder.proto``) with
the same rules as the ``boicp`` command line: the bearer token and TLS
checks, a 10 s deadline on every unary call, none on streams, uploads that
skip the bytes the daemon already holds, and paged results gathered whole.

Example::

    from boicp.client import Client, TlsOptions

    with Client("127.0.0.1:50051") as daemon:
        assert daemon.health() == "SERVING"
        job_id = daemon.submit("scans/kitti00", config="A", count=4)
        for event in daemon.watch(job_id):
            print(event.job.stage, event.job.pairs_done, "/", event.job.pairs_total)
        results = daemon.results(job_id)  # every pair and the trajectory
        daemon.export(job_id, "bt", "map.bt")
    # Beyond loopback: Client(addr, token_file="token", tls=TlsOptions("ca.pem"))

Errors: a call the daemon answers with a status other than OK raises
``DaemonError`` (``code``, ``message``); the client's own bad input raises
``ValueError`` (an unreadable token or TLS file too, as for the CLI); an
unreadable scan or an unwritable export path raises ``OSError``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import hashlib
import importlib
import os
import pathlib
from typing import Callable, Iterator, Optional, Sequence, Union

import grpc
from google.protobuf import wrappers_pb2

from boicp.v1 import map_builder_pb2 as pb
from boicp.v1 import map_builder_pb2_grpc as pb_grpc

__all__ = [
    "CHUNK_BYTES",
    "CONTROL_TIMEOUT_S",
    "EXPORT_FORMATS",
    "MAX_MESSAGE_BYTES",
    "Client",
    "ClientError",
    "DaemonError",
    "DaemonUnreachable",
    "ServingStatus",
    "TlsOptions",
    "Unauthenticated",
]

#: Deadline of every unary call, in seconds (the CLI's kControlTimeout).
CONTROL_TIMEOUT_S = 10.0
#: Largest message sent or received (the CLI's kMaxReceiveBytes): results
#: carry about 0.5 KB a scan, far beyond gRPC's 4 MiB default for big batches.
MAX_MESSAGE_BYTES = 256 << 20
#: Bytes per upload chunk, as rpc's MapBuilderClient::Upload.
CHUNK_BYTES = 1 << 20

#: The CLI's export format names (``boicp export --format``).
EXPORT_FORMATS = {
    "bt": pb.EXPORT_FORMAT_OCTOMAP_BT,
    "ot": pb.EXPORT_FORMAT_OCTOMAP_OT,
    "ply": pb.EXPORT_FORMAT_POINT_CLOUD_PLY,
    "tum": pb.EXPORT_FORMAT_TRAJECTORY_TUM,
    "kitti": pb.EXPORT_FORMAT_TRAJECTORY_KITTI,
}

_HEALTH_CHECK = "/grpc.health.v1.Health/Check"
_WHITESPACE = " \t\r\n"  # what the CLI and the daemon trim around a token

ProgressCallback = Callable[[int, int, int], None]
MetadataLike = Union[pb.ScanMetadata, bytes]


class ClientError(RuntimeError):
    """Base of the run-time errors of this module."""


class DaemonError(ClientError):
    """A call the daemon (or gRPC) ended with a status other than OK.

    ``rpc`` names the call, ``code`` is its ``grpc.StatusCode`` and
    ``message`` the daemon's message, which names the field at fault.
    """

    def __init__(self, rpc: str, code: grpc.StatusCode, message: str, text: Optional[str] = None):
        super().__init__(text or f"{rpc}: {message} ({code.name})")
        self.rpc = rpc
        self.code = code
        self.message = message


class DaemonUnreachable(DaemonError):
    """The daemon did not answer: UNAVAILABLE, or a unary call past its deadline."""


class Unauthenticated(DaemonError):
    """The daemon requires a token and got none, or the wrong one."""


class ServingStatus(str, enum.Enum):
    """``grpc.health.v1.HealthCheckResponse.ServingStatus``, by name."""

    UNKNOWN = "UNKNOWN"
    SERVING = "SERVING"
    NOT_SERVING = "NOT_SERVING"
    SERVICE_UNKNOWN = "SERVICE_UNKNOWN"


_SERVING_STATUS_BY_NUMBER = list(ServingStatus)  # the proto's numbering, 0 to 3


@dataclasses.dataclass(frozen=True)
class TlsOptions:
    """PEM files of a TLS daemon, as the CLI's ``--tls-ca/--tls-cert/--tls-key``.

    ``ca_file`` holds the roots that sign the daemon's certificate;
    ``cert_file`` and ``key_file`` (together) are a client certificate for
    a daemon run with ``--tls-client-ca``.
    """

    ca_file: Optional[str]
    cert_file: Optional[str] = None
    key_file: Optional[str] = None


def _read_bytes(path: str, what: str) -> bytes:
    try:
        with open(path, "rb") as f:
            return f.read()
    except OSError as e:
        raise ValueError(f"{what} {path}: cannot read ({e.strerror})") from None


def _resolve_token(token: Optional[str], token_file: Optional[str]) -> Optional[str]:
    if token is not None and token_file is not None:
        raise ValueError("token and token_file: give one, not both")
    what = "token"
    if token_file is not None:
        token = _read_bytes(token_file, "token_file").decode("utf-8")
        what = f"token_file {token_file}"
    if token is None:
        return None
    token = token.strip(_WHITESPACE)
    if not token:
        raise ValueError(f"{what}: empty")
    return token


def _ssl_credentials(tls: Union[TlsOptions, dict]) -> grpc.ChannelCredentials:
    if isinstance(tls, dict):
        try:
            tls = TlsOptions(**tls)
        except TypeError as e:
            raise ValueError(f"tls: {e}") from None
    # The CLI's checks (client/remote_options.cpp), in this API's names.
    if bool(tls.cert_file) != bool(tls.key_file):
        raise ValueError("tls: cert_file and key_file go together")
    if not tls.ca_file:
        raise ValueError("tls: cert_file needs ca_file" if tls.cert_file
                         else "tls: ca_file missing (the PEM roots of the daemon)")
    roots = _read_bytes(tls.ca_file, "tls ca_file")
    if not tls.cert_file:
        return grpc.ssl_channel_credentials(root_certificates=roots)
    return grpc.ssl_channel_credentials(
        root_certificates=roots,
        private_key=_read_bytes(tls.key_file, "tls key_file"),
        certificate_chain=_read_bytes(tls.cert_file, "tls cert_file"),
    )


def _as_metadata(metadata: MetadataLike) -> pb.ScanMetadata:
    if isinstance(metadata, pb.ScanMetadata):
        copy = pb.ScanMetadata()
        copy.CopyFrom(metadata)
        return copy
    return pb.ScanMetadata.FromString(metadata)


def _export_format(format: Union[str, int]) -> int:
    if isinstance(format, str):
        if format not in EXPORT_FORMATS:
            raise ValueError(f"format: unknown '{format}' (use bt, ot, ply, tum or kitti)")
        return EXPORT_FORMATS[format]
    if format not in EXPORT_FORMATS.values():
        raise ValueError(f"format: unknown ExportFormat {format}")
    return format


def _fsync_directory(path: str) -> None:
    # The rename is durable only once the directory entry is on disk.
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class Client:
    """A connection to one boicpd (``HOST:PORT``).

    ``token`` (or ``token_file``, a file holding it; surrounding whitespace
    is stripped and an empty token is an error) is sent as
    ``authorization: Bearer <token>`` on every MapBuilder call. A token
    needs ``tls`` (a ``TlsOptions`` or a dict of its fields) unless
    ``insecure=True`` allows it to travel in plaintext. The channel opens
    lazily: constructing a client sends nothing. Use it as a context manager,
    or call ``close()``.
    """

    def __init__(
        self,
        address: str,
        token: Optional[str] = None,
        tls: Union[TlsOptions, dict, None] = None,
        *,
        token_file: Optional[str] = None,
        insecure: bool = False,
    ):
        self.address = address
        token = _resolve_token(token, token_file)
        if token is not None and tls is None and not insecure:
            raise ValueError(
                "token: the token would cross the network in plaintext; give "
                "tls=TlsOptions(ca_file='CA.pem'), or insecure=True to send it anyway"
            )
        self._token_given = token is not None
        self._auth = (("authorization", "Bearer " + token),) if self._token_given else ()
        options = [
            ("grpc.max_receive_message_length", MAX_MESSAGE_BYTES),
            ("grpc.max_send_message_length", MAX_MESSAGE_BYTES),
        ]
        if tls is None:
            self._channel = grpc.insecure_channel(address, options=options)
        else:
            self._channel = grpc.secure_channel(address, _ssl_credentials(tls), options=options)
        self._stub = pb_grpc.MapBuilderStub(self._channel)

    def close(self) -> None:
        """Closes the channel; calls in flight end with CANCELLED."""
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    # -- errors ---------------------------------------------------------------

    def _error(self, rpc: str, error: grpc.RpcError, unary: bool) -> DaemonError:
        """The exception for a failed call, worded as the CLI words it."""
        code, message = error.code(), error.details() or ""
        if code == grpc.StatusCode.UNAVAILABLE:
            text = f"{rpc}: cannot reach the daemon at {self.address} ({message})"
            return DaemonUnreachable(rpc, code, message, text)
        # A unary call's deadline is ours; a stream's comes from the daemon,
        # whose message names the limit.
        if code == grpc.StatusCode.DEADLINE_EXCEEDED and unary:
            text = (f"{rpc}: no answer from the daemon at {self.address} "
                    f"within {CONTROL_TIMEOUT_S:g} s")
            return DaemonUnreachable(rpc, code, message, text)
        if code == grpc.StatusCode.UNAUTHENTICATED:
            text = (f"{rpc}: the daemon at {self.address} rejected the token ({message})"
                    if self._token_given else
                    f"{rpc}: the daemon at {self.address} requires a token: pass token= or "
                    f"token_file= (the file given to boicpd --token-file)")
            return Unauthenticated(rpc, code, message, text)
        return DaemonError(rpc, code, message)

    def _unary(self, rpc: str, request):
        """Calls a unary method with the token and the control deadline."""
        try:
            return getattr(self._stub, rpc)(request, timeout=CONTROL_TIMEOUT_S, metadata=self._auth)
        except grpc.RpcError as e:
            raise self._error(rpc, e, unary=True) from None

    # -- health ---------------------------------------------------------------

    def health(self, service: str = "") -> ServingStatus:
        """The daemon's ``grpc.health.v1.Health/Check`` status for ``service``.

        ``ServingStatus.SERVING`` (equal to the string ``"SERVING"``), or
        ``NOT_SERVING`` while the daemon drains. Sent without the token:
        the daemon keeps health open for probes.
        """
        # Debian's python3-grpcio has no grpc_health module. HealthCheckRequest
        # ({string service = 1}) and HealthCheckResponse ({enum status = 1})
        # have the wire format of StringValue and Int32Value, which protobuf
        # ships, so they stand in for the health stubs.
        check = self._channel.unary_unary(
            _HEALTH_CHECK,
            request_serializer=wrappers_pb2.StringValue.SerializeToString,
            response_deserializer=wrappers_pb2.Int32Value.FromString,
        )
        try:
            response = check(wrappers_pb2.StringValue(value=service), timeout=CONTROL_TIMEOUT_S)
        except grpc.RpcError as e:
            raise self._error("Check", e, unary=True) from None
        known = 0 <= response.value < len(_SERVING_STATUS_BY_NUMBER)
        return _SERVING_STATUS_BY_NUMBER[response.value] if known else ServingStatus.UNKNOWN

    # -- scans ----------------------------------------------------------------

    def _missing(self, scan_id: str) -> bool:
        found = self._unary("FindScans", pb.FindScansRequest(scan_ids=[scan_id]))
        return bool(found.missing)

    def _send_scan(self, metadata: pb.ScanMetadata, data: bytes,
                   with_bytes: bool) -> pb.UploadScanResponse:
        def messages():
            yield pb.UploadScanRequest(metadata=metadata)
            if with_bytes:
                for at in range(0, len(data), CHUNK_BYTES):
                    yield pb.UploadScanRequest(chunk=data[at:at + CHUNK_BYTES])

        return self._stub.UploadScan(messages(), metadata=self._auth)

    def upload_scan(self, path: str, metadata: MetadataLike) -> pb.UploadScanResponse:
        """Uploads one scan file; returns the daemon's ``UploadScanResponse``.

        ``metadata`` is a ``ScanMetadata`` (or its serialized bytes) with at
        least the format; its ``size_bytes`` and ``sha256`` are filled in
        here. When the daemon already holds the bytes only the metadata is
        sent and the response has ``already_present``; should the daemon's
        copy then fail its hash check (``DATA_LOSS``) the bytes are sent
        after all. As rpc's ``MapBuilderClient::Upload``.
        """
        with open(path, "rb") as f:
            return self._upload_bytes(f.read(), metadata)

    def _upload_bytes(self, data: bytes, metadata: MetadataLike) -> pb.UploadScanResponse:
        message = _as_metadata(metadata)
        message.sha256 = hashlib.sha256(data).hexdigest()
        message.size_bytes = len(data)
        # Ask first, so that a scan the daemon holds costs one small call.
        present = not self._missing(message.sha256)
        try:
            try:
                return self._send_scan(message, data, with_bytes=not present)
            except grpc.RpcError as e:
                if not (present and e.code() == grpc.StatusCode.DATA_LOSS):
                    raise
            # The daemon's copy failed its hash check and was set aside.
            return self._send_scan(message, data, with_bytes=True)
        except grpc.RpcError as e:
            raise self._error("UploadScan", e, unary=False) from None

    def upload_scans(self, paths: Sequence[str], metadata_list: Sequence[MetadataLike],
                     progress: Optional[ProgressCallback] = None) -> list:
        """Uploads scan files in order; returns their scan ids (SHA-256).

        ``metadata_list[i]`` goes with ``paths[i]`` (see ``upload_scan``).
        ``progress(done, total, sent_bytes)``, if given, is called after each
        scan; ``sent_bytes`` counts the bytes of scans the daemon lacked.
        """
        if len(paths) != len(metadata_list):
            raise ValueError(f"upload_scans: {len(paths)} paths but "
                             f"{len(metadata_list)} metadata entries")
        return self._upload_all(lambda i: pathlib.Path(paths[i]).read_bytes(), metadata_list,
                                progress)

    def _upload_all(self, read: Callable[[int], bytes], metadata_list: Sequence[MetadataLike],
                    progress: Optional[ProgressCallback]) -> list:
        """Uploads scan i's bytes, ``read(i)``, with ``metadata_list[i]``, in order."""
        ids = []
        sent_bytes = 0
        for done, metadata in enumerate(metadata_list, start=1):
            response = self._upload_bytes(read(done - 1), metadata)
            ids.append(response.scan_id)
            if not response.already_present:
                sent_bytes += response.size_bytes
            if progress is not None:
                progress(done, len(metadata_list), sent_bytes)
        return ids

    # -- jobs -----------------------------------------------------------------

    def submit(self, scans: Union[str, os.PathLike, Sequence[Union[str, os.PathLike]]], *,
               label: Optional[str] = None, progress: Optional[ProgressCallback] = None,
               **settings) -> str:
        """Submits a folder of scans or a bag as ``boicp submit PATH`` does; returns the job id.

        ``scans`` is the folder or the bag (``.bag``, ``.db3``, ``.mcap`` or a
        ROS 2 bag folder; ``topic``, ``odometry_topic``, ``start`` and
        ``duration`` as ``boicp.build_map`` takes them), or a list of scan
        files (their formats from their extensions; depth images need
        ``intrinsics`` and ``depth_scale``). A bag's scans are uploaded as
        ``boicp submit`` uploads them, one at a time, each as the binary PCD
        of its points.

        ``settings`` are named as ``boicp.build_map`` takes them (``config``, ``voxel``,
        ``seed``, ``resolution``, ``pairing``, ``first``, ``stride``,
        ``count``, ``layout``, ``poses_as_priors``...). The batch is planned
        by the CLI's own code (``boicp._boicp.plan_submission``, which raises
        ``ValueError`` with the CLI's message on bad input), every scan is
        uploaded (``progress`` as in ``upload_scans``), and the batch is
        submitted. ``label`` replaces the default label (the folder, or the
        first file's folder).
        """
        # The compiled module is only needed here: the rest of the client is
        # pure Python.
        planner = importlib.import_module("boicp._boicp")
        # Reachable and the token accepted before the plan's checks, which may
        # load every scan: as the CLI, fail fast on the daemon.
        self._unary("ListJobs", pb.ListJobsRequest(page_size=1))
        listed = not isinstance(scans, (str, os.PathLike))
        plan = planner.plan_submission([os.fspath(s) for s in scans] if listed else os.fspath(scans),
                                       settings)
        request = pb.SubmitBatchRequest.FromString(plan["request"])
        request.scan_ids[:] = self._upload_all(
            plan["read"], [scan["metadata"] for scan in plan["scans"]], progress)
        if label is not None:
            request.label = label
        return self._unary("SubmitBatch", request).job_id

    def get_job(self, job_id: str) -> pb.Job:
        """The job's current state (``GetJob``)."""
        return self._unary("GetJob", pb.GetJobRequest(job_id=job_id))

    def list_jobs(self, limit: int = 50) -> list:
        """Up to ``limit`` jobs (0 = all), newest first, as ``boicp jobs --limit``."""
        jobs = []
        token = ""
        while True:
            page_size = min(limit, 500) if limit > 0 else 500
            page = self._unary("ListJobs", pb.ListJobsRequest(page_size=page_size,
                                                              page_token=token))
            jobs.extend(page.jobs)
            token = page.next_page_token
            if not token or 0 < limit <= len(jobs):
                return jobs[:limit] if limit > 0 else jobs

    def cancel(self, job_id: str) -> pb.Job:
        """Asks the daemon to cancel the job; returns it as the daemon then sees it.

        A queued job comes back CANCELLED; a running one with
        ``cancel_requested`` (it stops within seconds: follow it with
        ``watch``); a finished one unchanged.
        """
        return self._unary("CancelJob", pb.CancelJobRequest(job_id=job_id))

    def delete(self, job_id: str) -> pb.DeleteJobResponse:
        """Deletes a finished job's record and outputs (``FAILED_PRECONDITION`` while it runs)."""
        return self._unary("DeleteJob", pb.DeleteJobRequest(job_id=job_id))

    def watch(self, job_id: str) -> Iterator[pb.JobEvent]:
        """Yields the job's ``JobEvent`` messages until it ends.

        The first event is a snapshot; then one per stage change, per
        finished pair (``event.pair`` set) and each second of progress. The
        generator ends after the event with a final state (``event.job.state``
        SUCCEEDED, FAILED or CANCELLED); a watcher too slow to keep up gets
        ``pairs_skipped`` (``results`` has every pair). No deadline; closing
        the generator early cancels the stream, not the job.
        """
        call = self._stub.WatchJob(pb.WatchJobRequest(job_id=job_id), metadata=self._auth)
        try:
            yield from call
        except grpc.RpcError as e:
            raise self._error("WatchJob", e, unary=False) from None
        finally:
            call.cancel()  # a no-op once the stream ended

    def results(self, job_id: str, page_size: int = 0) -> pb.JobResults:
        """Every pair result and trajectory pose of the job, gathered page by page.

        ``page_size`` pairs (and poses) per ``GetResults`` call; 0 = the
        daemon's maximum (2000). The ``job`` is the first page's.
        """
        results = pb.JobResults()
        request = pb.GetResultsRequest(job_id=job_id, page_size=page_size)
        while True:
            page = self._unary("GetResults", request)
            if page.next_page_token and page.next_page_token == request.page_token:
                raise ClientError("GetResults: the daemon returned the same page token twice")
            if not results.HasField("job"):
                results.job.CopyFrom(page.job)
            results.pairs.extend(page.pairs)
            results.trajectory.extend(page.trajectory)
            if not page.next_page_token:
                return results
            request.page_token = page.next_page_token

    def export(self, job_id: str, format: Union[str, int], path: str) -> str:
        """Downloads one output of a succeeded job to ``path``; returns ``path``.

        ``format`` is ``"bt"``, ``"ot"``, ``"ply"``, ``"tum"``, ``"kitti"``
        or an ``ExportFormat`` value. The bytes go to ``path + ".part"``,
        which is synced and renamed over ``path`` once complete, so a reader
        never sees half a file; on failure the ``.part`` file is removed.
        """
        request = pb.ExportRequest(job_id=job_id, format=_export_format(format))
        part = path + ".part"
        try:
            self._download(request, part)
            os.replace(part, path)
        except BaseException:
            with contextlib.suppress(FileNotFoundError):
                os.remove(part)
            raise
        _fsync_directory(os.path.dirname(os.path.abspath(path)))
        return path

    def _download(self, request: pb.ExportRequest, part: str) -> None:
        """Streams an export into ``part`` and syncs it; checks the size."""
        written, expected = 0, None
        with open(part, "wb") as out:
            try:
                for chunk in self._stub.Export(request, metadata=self._auth):
                    if expected is None:
                        expected = chunk.total_size
                    out.write(chunk.data)
                    written += len(chunk.data)
            except grpc.RpcError as e:
                raise self._error("Export", e, unary=False) from None
            out.flush()
            os.fsync(out.fileno())
        if written != (expected or 0):
            raise ClientError(f"Export: got {written} of {expected or 0} bytes")
