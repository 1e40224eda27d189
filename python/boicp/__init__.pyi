from typing import Any, Callable, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

Points = npt.NDArray[Union[np.float64, np.float32]]

class Result:
    transform: npt.NDArray[np.float64]
    fitness: float
    rmse: float
    confidence: float
    doubtful: bool
    evaluations: int
    answered_by: str
    attempts: List[Dict[str, Any]]
    settings: Dict[str, Any]
    def __init__(self, report: Dict[str, Any]) -> None: ...
    def to_dict(self) -> Dict[str, Any]: ...

def register(
    source: Points,
    target: Points,
    *,
    config: str = ...,
    budget: Optional[str] = ...,
    prior: Optional[npt.ArrayLike] = ...,
    seed: int = ...,
    threads: int = ...,
    **settings: Any,
) -> Result: ...
def read_scan(
    path: str,
    format: str = ...,
    *,
    intrinsics: Optional[Union[str, Sequence[float]]] = ...,
    intrinsics_file: str = ...,
    depth_scale: float = ...,
    invalid_depth: Sequence[int] = ...,
    max_points: int = ...,
) -> npt.NDArray[np.float64]: ...
def build_map(
    folder: str,
    out_dir: str,
    *,
    progress: Optional[Callable[[Dict[str, Any]], None]] = ...,
    threads: int = ...,
    max_fusion_mb: int = ...,
    **settings: Any,
) -> Dict[str, Any]: ...
