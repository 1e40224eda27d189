"""boicp: point-cloud registration that needs no initial guess (BO-ICP), and maps.

The same engine, settings and answers as the ``boicp`` command line::

    import boicp

    source = boicp.read_scan("velodyne/000001.bin")
    target = boicp.read_scan("velodyne/000000.bin")
    result = boicp.register(source, target)  # T_target_source, metres
    print(result.transform, result.confidence, result.doubtful)

    summary = boicp.build_map("drive/", "out/", progress=print)
    print(summary["outputs"]["map.bt"])

Settings are keyword arguments named as the settings schema names them
(``voxel=0.05``, ``translation_bounds=(0.5, 0.5, 0.5)``, ``budget="fixed"``);
a bad one raises ValueError with the command line's message. The engine runs
without the GIL, and Ctrl-C stops it. ``boicp.client`` talks to a boicpd
daemon.
"""

import json

import numpy as np

from . import _boicp

__version__ = _boicp.__version__
__all__ = ["Result", "register", "read_scan", "build_map", "__version__"]


class Result:
    """One registration's answer, as ``boicp register --json`` reports it.

    transform: 4 x 4 numpy array T_target_source (p_target = T @ p_source), metres.
    fitness: share of source points within the inlier distance of the target.
    rmse: RMS distance of those inliers, metres.
    confidence: in [0, 1], how far the answer is to be trusted.
    doubtful: confidence below 0.95; check or re-run such a pair.
    evaluations: ICP runs of every rung together.
    answered_by: the ladder's rung whose answer was kept.
    attempts: one dict per attempt (kind, mode, seed, fitness, confidence, ...).
    settings: the settings used, every automatic one resolved.
    """

    def __init__(self, report):
        self._report = report
        self.transform = np.array(report["transform"], dtype=np.float64)
        self.fitness = report["fitness"]
        self.rmse = report["inlier_rmse"]
        self.confidence = report["confidence"]
        self.doubtful = report["doubtful"]
        self.evaluations = report["evaluations"]
        self.answered_by = report["answered_by"]
        self.attempts = report["attempts"]
        self.settings = report["config"]

    def to_dict(self):
        """The ``boicp register --json`` object (a deep copy)."""
        return json.loads(json.dumps(self._report))

    def __repr__(self):
        return (f"Result(fitness={self.fitness:.3f}, rmse={self.rmse:.4f}, "
                f"confidence={self.confidence:.3f}, doubtful={self.doubtful}, "
                f"answered_by={self.answered_by!r}, evaluations={self.evaluations})")


def _settings(settings, **named):
    """The keyword settings with the named parameters that were given."""
    out = dict(settings)
    for name, value in named.items():
        if value is not None:
            out[name] = value
    return out


def register(source, target, *, config="C", budget=None, prior=None, seed=1, threads=0,
             **settings):
    """Registers ``source`` onto ``target``; returns a Result (T_target_source).

    source, target: (N, 3) float64 or float32 arrays of points, metres, each in
        its sensor's frame (non-finite points are an error). A float64 array
        whose rows hold x, y, z side by side (C order, or the first three
        columns of a wider C-order array) is read where it lies, not copied;
        do not change it while register runs.
    config: the paper's preset, "A", "B" or "C".
    budget: "auto" (the escalation ladder, the default) or "fixed" (the
        paper's full search).
    prior: an initial guess, 4 x 4 T_target_source (odometry, say).
    seed: every random choice derives from it; the same seed and settings
        give the same answer as ``boicp register``, bit for bit.
    threads: threads of the registration; 0 = every core.
    settings: any registration setting by name (voxel, rotation_bounds,
        translation_bounds, sensor, mode, no_retry, ...).
    """
    given = _settings(settings, preset=config, budget=budget, seed=seed,
                      threads=threads if threads > 0 else None)
    return Result(_boicp.register_clouds(source, target, given, prior))


def read_scan(path, format="auto", *, intrinsics=None, intrinsics_file="", depth_scale=0.0,
              invalid_depth=(0, 65535), max_points=5_000_000):
    """The points of a scan file as an (N, 3) float64 array, metres, non-finite dropped.

    The array owns the points as the loader read them (no copy), and register
    reads it in place.

    format: "auto" (from the extension), "kitti", "pcd", "ply", "xyz" or "depth".
    intrinsics: a depth image's camera, (fx, fy, cx, cy) in pixels or "fx,fy,cx,cy";
        intrinsics_file: a file with fx fy cx cy or a 3 x 3 K.
    depth_scale: depth units per metre (TUM 5000, 7-Scenes 1000).
    invalid_depth: raw depth values that mean no data.
    max_points: a file declaring more points is refused before it is read.
    """
    if intrinsics is not None and not isinstance(intrinsics, str):
        intrinsics = ",".join(repr(float(v)) for v in intrinsics)
    return _boicp.read_scan(str(path), format, intrinsics or "", str(intrinsics_file),
                            float(depth_scale), list(invalid_depth), int(max_points))


def build_map(folder, out_dir, *, progress=None, threads=0, max_fusion_mb=0, **settings):
    """Builds the map of a folder of scans or a bag, as ``boicp map FOLDER -o OUT_DIR`` does.

    Writes map.bt, map.ot, trajectory.tum, trajectory.kitti, pairs.json,
    preview.png, run.json and pairs/ into out_dir; a second run reuses the
    pair files whose settings match. Returns ``boicp map --json``'s summary.

    progress: called with one dict per event: {"event": "pair", "source",
        "target", "reused", "confidence", "doubtful", "answered_by", "done",
        "total", "doubtful_total"}, {"event": "stage", "stage", "total"} and
        {"event": "fusing", "stage", "done", "total"}. An exception it
        raises stops the run and is raised here.
    threads: pairs registered at once; 0 = every core (the map does not
        depend on it).
    max_fusion_mb: refuse a map estimated to need more memory; 0 = no limit.
    settings: the map's settings by name (config, voxel, resolution,
        max_range, ...) and run.json's folder and pairing keys (layout,
        first, stride, count, pairing, pairs_file, overlap_threshold,
        extra_pairs_file, intrinsics, camera, depth_scale, poses_as_priors,
        more_paths: further drives of the same place, as ``boicp map A B``)
        and, for a bag, topic, odometry_topic, start, duration and
        min_interval.
    """
    return _boicp.build_map(str(folder), str(out_dir), settings, int(threads),
                            int(max_fusion_mb), progress)
