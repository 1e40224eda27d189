#!/usr/bin/env python3
"""Runs the commands written in the compose file and the Kubernetes batch Jobs
against the built binaries, outside any container, with the container paths
(/scans, /out, /data) mapped to a temporary folder.

Usage: run_deploy_commands.py MODE --root SRC --bin-dir BIN --shared-data DIR
  compose-submit  the compose `submit` service's script against a loopback
                  boicpd on a generated pair; checks the exported files
  k8s-batch       every pod of the Indexed shard Job, then the merge Job, on
                  the first scans of kitti00; checks the merged outputs
Exits 1 on a failure, 77 (a ctest skip) when the data or a subcommand is absent.
"""

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import yaml  # python3-yaml, a dependency of yamllint

SKIP = 77
OCTOMAP_BINARY_HEADER = "# Octomap OcTree binary file"


class Failure(Exception):
    pass


def load(path):
    with open(path, encoding="utf-8") as f:
        return [d for d in yaml.safe_load_all(f) if d]


def run_script(words, env, remap, cwd):
    """Runs a container command (a list of words) with container paths remapped."""
    words = [remap_paths(w, remap) for w in words]
    result = subprocess.run(words, env=env, cwd=cwd, capture_output=True, text=True, timeout=1800)
    if result.returncode != 0:
        raise Failure(f"{words} exited {result.returncode}:\n{result.stdout}{result.stderr}")
    return result


def remap_paths(word, remap):
    """Replaces whole container paths (longest first) in one pass."""
    alternatives = "|".join(re.escape(p) for p in sorted(remap, key=len, reverse=True))
    pattern = r"(?<![\w/])(" + alternatives + r")(?![\w.-])"
    return re.sub(pattern, lambda m: remap[m.group(1)], word)


def base_env(bin_dir):
    env = dict(os.environ)
    env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "")
    return env


def has_subcommand(boicp, name, flag=None):
    listing = subprocess.run([boicp, "--help"], capture_output=True, text=True).stdout
    if not re.search(rf"^\s+{name}\s", listing, re.M):
        return False
    if flag is None:
        return True
    help_text = subprocess.run([boicp, name, "--help"], capture_output=True, text=True).stdout
    return flag in help_text


def check_outputs(folder, names, scans):
    for name in names:
        path = os.path.join(folder, name)
        if not os.path.isfile(path) or os.path.getsize(path) == 0:
            raise Failure(f"{path} missing or empty")
    with open(os.path.join(folder, "map.bt"), "rb") as f:
        if not f.readline().decode(errors="replace").startswith(OCTOMAP_BINARY_HEADER):
            raise Failure(f"{folder}/map.bt is not an OctoMap binary file")
    with open(os.path.join(folder, "trajectory.tum"), encoding="utf-8") as f:
        poses = [l for l in f if l.strip() and not l.startswith("#")]
    if len(poses) != scans:
        raise Failure(f"{folder}/trajectory.tum has {len(poses)} poses, want {scans}")


# ------------------------------------------------------------ compose submit


class Daemon:
    """boicpd on a free loopback port, configured by variables as in compose."""

    def __init__(self, bin_dir, data_dir, log_path, token_file):
        env = base_env(bin_dir)
        env.update(BOICPD_LISTEN="127.0.0.1:0", BOICPD_DATA_DIR=data_dir, BOICPD_WORKERS="1",
                   BOICPD_AUTH_TOKEN_FILE=token_file)
        self.log_path = log_path
        self.log = open(log_path, "w", encoding="utf-8")
        self.process = subprocess.Popen(
            [os.path.join(bin_dir, "boicpd")], env=env, stdout=self.log, stderr=subprocess.STDOUT
        )
        self.address = self._wait_for_address()

    def _wait_for_address(self):
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            with open(self.log_path, encoding="utf-8") as f:
                m = re.search(r"listening on (\S+)", f.read())
            if m:
                return m.group(1)
            if self.process.poll() is not None:
                raise Failure("boicpd exited before listening")
            time.sleep(0.1)
        raise Failure("boicpd did not start within 60 s")

    def stop(self):
        """SIGTERM, as docker stop sends; the exit code, or None if it hung."""
        code = None
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
            try:
                code = self.process.wait(timeout=60)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        else:
            code = self.process.returncode
        self.log.close()
        return code


def compose_submit(args, tmp):
    compose = load(os.path.join(args.root, "deploy", "docker-compose.yml"))[0]
    service = compose["services"]["submit"]
    # Compose turns $$ into $ before the shell sees the script.
    words = [w.replace("$$", "$") for w in service["command"]]
    scans, out = os.path.join(tmp, "scans"), os.path.join(tmp, "out")
    os.makedirs(out)
    subprocess.run(
        [os.path.join(args.bin_dir, "boicp"), "demo-data", "-o", os.path.join(tmp, "demo")],
        check=True, capture_output=True,
    )
    os.makedirs(scans)
    for name in ("source.xyz", "target.xyz"):
        os.rename(os.path.join(tmp, "demo", name), os.path.join(scans, name))

    # The compose file mounts the token at the daemon's BOICPD_AUTH_TOKEN_FILE
    # and the client's --token-file alike.
    token_target = compose["services"]["boicpd"]["environment"]["BOICPD_AUTH_TOKEN_FILE"]
    token = os.path.join(tmp, "token")
    with open(token, "w", encoding="utf-8") as f:
        f.write("compose-test-token\n")
    daemon = Daemon(args.bin_dir, os.path.join(tmp, "data"), os.path.join(tmp, "boicpd.log"), token)
    try:
        env = base_env(args.bin_dir)
        env.update(BOICP_SERVER=daemon.address, BOICP_CONFIG="A")
        run_script(words, env, {"/scans": scans, "/out": out, token_target: token}, tmp)
    finally:
        code = daemon.stop()
    if code != 0:
        raise Failure(f"boicpd exited {code} after SIGTERM")
    check_outputs(out, ["map.bt", "map.ot", "map.ply", "trajectory.tum", "trajectory.kitti"], 2)


# ----------------------------------------------------------------- k8s batch


def job_container(path):
    job = load(path)[0]
    container = job["spec"]["template"]["spec"]["containers"][0]
    env = {e["name"]: str(e.get("value", "")) for e in container.get("env", [])}
    return job, container.get("command", []) + container.get("args", []), env


def k8s_batch(args, tmp):
    boicp = os.path.join(args.bin_dir, "boicp")
    if not (has_subcommand(boicp, "map", "--shard") and has_subcommand(boicp, "merge")):
        print("boicp has no `map --shard` or `merge` yet")
        return SKIP
    kitti = os.path.join(args.shared_data, "kitti00")
    if not os.path.isdir(kitti):
        print(f"{kitti} absent: skipping the batch run")
        return SKIP
    batch = os.path.join(args.root, "deploy", "k8s", "batch")
    job, shard_words, shard_env = job_container(os.path.join(batch, "map-shards-job.yaml"))
    _, merge_words, merge_env = job_container(os.path.join(batch, "merge-job.yaml"))
    remap = {"/data/scans": kitti, "/data": tmp}
    scans = 4
    for index in range(int(job["spec"]["completions"])):
        env = base_env(args.bin_dir)
        env.update(shard_env)
        # Short and cheap: the first scans, preset A (flags as an operator would add them).
        env.update(JOB_COMPLETION_INDEX=str(index), BOICP_CONFIG="A")
        env["BOICP_MAP_ARGS"] = f"--count {scans} --rotation-bounds 0.2,0.2,3.14159"
        run_script(shard_words, env, remap, tmp)
    env = base_env(args.bin_dir)
    env.update(merge_env)
    run_script(merge_words, env, remap, tmp)
    names = ["map.bt", "map.ot", "trajectory.tum", "trajectory.kitti", "pairs.json", "preview.png"]
    check_outputs(os.path.join(tmp, "out"), names, scans)
    return 0


MODES = {"compose-submit": compose_submit, "k8s-batch": k8s_batch}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", choices=sorted(MODES))
    parser.add_argument("--root", required=True)
    parser.add_argument("--bin-dir", required=True)
    parser.add_argument("--shared-data", required=True)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        try:
            code = MODES[args.mode](args, tmp) or 0
        except (Failure, subprocess.SubprocessError) as e:
            print(f"{args.mode}: FAIL: {e}")
            return 1
    print(f"{args.mode}: {'ok' if code == 0 else 'skipped'}")
    return code


if __name__ == "__main__":
    sys.exit(main())
