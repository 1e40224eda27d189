"""Type stubs of boicp.client (see client.py for the documentation)."""

import enum
import os
from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Sequence, Union

import grpc

from boicp.v1 import map_builder_pb2 as pb

CONTROL_TIMEOUT_S: float
MAX_MESSAGE_BYTES: int
CHUNK_BYTES: int
EXPORT_FORMATS: Dict[str, int]

ProgressCallback = Callable[[int, int, int], None]
MetadataLike = Union[pb.ScanMetadata, bytes]

class ClientError(RuntimeError): ...

class DaemonError(ClientError):
    rpc: str
    code: grpc.StatusCode
    message: str
    def __init__(
        self, rpc: str, code: grpc.StatusCode, message: str, text: Optional[str] = ...
    ) -> None: ...

class DaemonUnreachable(DaemonError): ...
class Unauthenticated(DaemonError): ...

class ServingStatus(str, enum.Enum):
    UNKNOWN: str
    SERVING: str
    NOT_SERVING: str
    SERVICE_UNKNOWN: str

class TlsOptions:
    ca_file: Optional[str]
    cert_file: Optional[str]
    key_file: Optional[str]
    def __init__(
        self, ca_file: Optional[str], cert_file: Optional[str] = ..., key_file: Optional[str] = ...
    ) -> None: ...

class Client:
    address: str
    def __init__(
        self,
        address: str,
        token: Optional[str] = ...,
        tls: Union[TlsOptions, Mapping[str, Optional[str]], None] = ...,
        *,
        token_file: Optional[str] = ...,
        insecure: bool = ...,
    ) -> None: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Client": ...
    def __exit__(self, *exc_info: Any) -> None: ...
    def health(self, service: str = ...) -> ServingStatus: ...
    def upload_scan(self, path: str, metadata: MetadataLike) -> pb.UploadScanResponse: ...
    def upload_scans(
        self,
        paths: Sequence[str],
        metadata_list: Sequence[MetadataLike],
        progress: Optional[ProgressCallback] = ...,
    ) -> List[str]: ...
    def submit(
        self,
        scans: Union[str, os.PathLike, Sequence[Union[str, os.PathLike]]],
        *,
        label: Optional[str] = ...,
        progress: Optional[ProgressCallback] = ...,
        **settings: Any,
    ) -> str: ...
    def get_job(self, job_id: str) -> pb.Job: ...
    def list_jobs(self, limit: int = ...) -> List[pb.Job]: ...
    def cancel(self, job_id: str) -> pb.Job: ...
    def delete(self, job_id: str) -> pb.DeleteJobResponse: ...
    def watch(self, job_id: str) -> Iterator[pb.JobEvent]: ...
    def results(self, job_id: str, page_size: int = ...) -> pb.JobResults: ...
    def export(self, job_id: str, format: Union[str, int], path: str) -> str: ...
