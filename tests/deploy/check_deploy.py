#!/usr/bin/env python3
"""Keeps the deployment files in step with the build, without Docker or a cluster.

Usage: check_deploy.py CHECK --root SRC --build-dir BUILD --boicpd PATH --boicp PATH
CHECK is one of: dockerfile, runtime-packages, manifests, batch-commands, readme-table.
Prints one line per problem and exits 1 when there is any; 77 (ctest's skip
code here) when a tool the check needs is missing.
"""

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys

SKIP = 77


# ---------------------------------------------------------------- helpers


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def run(args):
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout


def package_lists(root):
    script = os.path.join(root, "deploy", "install-deps.sh")
    build = run(["bash", script, "--list"]).split()
    runtime = run(["bash", script, "--list-runtime"]).split()
    return build, runtime


def daemon_env_options(boicpd):
    """{flag: (env, default or None)} from `boicpd --help`, the code's own view."""
    # "--name[,--alias] [TYPE[=default]] [REQUIRED] (Env:VAR)"; flags have no TYPE.
    pattern = re.compile(
        r"^\s+(--[a-z-]+)(?:,--[a-z-]+)*(?: [A-Z]+(?:=(\S+))?)?(?: REQUIRED)? \(Env:(\w+)\)")
    options = {}
    for line in run([boicpd, "--help"]).splitlines():
        m = pattern.match(line)
        if m:
            options[m.group(1)] = (m.group(3), m.group(2))
    return options


def project_version(root):
    m = re.search(r"project\(boicp VERSION (\S+)", read(os.path.join(root, "CMakeLists.txt")))
    return m.group(1)


# ---------------------------------------------------------- Dockerfile parse


def dockerfile_instructions(text):
    """[(stage_index, INSTRUCTION, argument)] with continuations joined."""
    logical, current = [], ""
    for line in text.splitlines():
        if not current and (not line.strip() or line.lstrip().startswith("#")):
            continue
        if line.rstrip().endswith("\\"):
            current += line.rstrip()[:-1] + " "
            continue
        logical.append(current + line)
        current = ""
    result, stage = [], -1
    for line in logical:
        keyword, _, argument = line.strip().partition(" ")
        keyword = keyword.upper()
        if keyword == "FROM":
            stage += 1
        result.append((stage, keyword, argument.strip()))
    return result


def shell_commands(argument):
    """The simple commands of a RUN line: its words, split at && || ; and |."""
    lexer = shlex.shlex(argument, posix=True, punctuation_chars=True)
    lexer.whitespace_split = True
    commands, words = [], []
    for token in lexer:
        if token in ("&&", "||", ";", "|", "&"):
            commands.append(words)
            words = []
        else:
            words.append(token)
    return [c for c in commands + [words] if c]


def configure_flags(commands):
    """The -D/-G options of the `cmake -S ... -B build` command (the main build tree;
    .ci/run may configure other trees, e.g. for sanitizers, after it)."""
    for words in commands:
        if words[:1] == ["cmake"] and "-S" in words and "-B" in words:
            if words[words.index("-B") + 1] == "build":
                return sorted(w for w in words if w.startswith(("-D", "-G")))
    return None


def exec_form(argument):
    m = re.search(r"\[.*\]", argument)
    return [w.strip().strip('"') for w in m.group(0)[1:-1].split(",")] if m else shlex.split(argument)


# ------------------------------------------------------------------ checks


def check_dockerfile(args):
    problems = []
    root = args.root
    instructions = dockerfile_instructions(read(os.path.join(root, "Dockerfile")))
    build_packages, runtime_packages = package_lists(root)
    env_options = daemon_env_options(args.boicpd)
    known_env = {env for env, _ in env_options.values()}

    stages = stage_names(instructions)
    want = [("debian:bookworm", "build"), ("debian:bookworm-slim", "base"), ("base", "prebuilt"),
            ("base", "runtime")]
    if stages != want:
        problems.append(f"Dockerfile: want the stages {want}, got {stages}")
        return problems
    build, base = 0, 1
    runs = [(stage, a) for stage, k, a in instructions if k == "RUN"]
    problems += check_apt_and_deps_script(runs, build, base, build_packages, runtime_packages)
    problems += check_build_flags(root, runs)
    problems += check_build_targets(args, runs, build)
    problems += check_copied_binaries(args, instructions, stages)
    problems += check_base_stage(instructions, known_env, root, base)
    return problems


def stage_names(instructions):
    """[(base image, stage name)] of each FROM, in order."""
    stages = []
    for _, keyword, argument in instructions:
        if keyword == "FROM":
            words = argument.split()
            stages.append((words[0], words[2] if len(words) > 2 and words[1].upper() == "AS" else ""))
    return stages


def check_apt_and_deps_script(runs, build, base, build_packages, runtime_packages):
    problems, used_deps_script = [], {}
    allowed = set(build_packages) | set(runtime_packages)
    for stage, argument in runs:
        for words in shell_commands(argument):
            runs_script = words[0] in ("bash", "sh") and words[1:2] or words[:1]
            if runs_script and runs_script[0].endswith("install-deps.sh"):
                used_deps_script[stage] = [w for w in words if w.startswith("--")]
            if len(words) > 2 and words[0] in ("apt-get", "apt") and "install" in words:
                extra = [w for w in words[words.index("install") + 1 :] if not w.startswith("-")]
                problems += [
                    f"Dockerfile: apt package {p} is not in install-deps.sh --list or --list-runtime"
                    for p in extra
                    if p not in allowed
                ]
    if used_deps_script.get(build) != []:
        problems.append("Dockerfile: the build stage must run deploy/install-deps.sh with no flags")
    if used_deps_script.get(base) != ["--runtime"]:
        problems.append("Dockerfile: the base stage must run deploy/install-deps.sh --runtime")
    return problems


def check_build_flags(root, runs):
    ci = read(os.path.join(root, ".ci", "run"))
    lines = ci.replace("\\\n", " ").splitlines()
    ci_commands = [c for line in lines if not line.startswith("#") for c in shell_commands(line)]
    ci_flags = configure_flags(ci_commands)
    docker_flags = None
    for _, argument in runs:
        docker_flags = docker_flags or configure_flags(shell_commands(argument))
    if ci_flags is None:
        return [".ci/run: no `cmake -S` configure line found"]
    if docker_flags != ci_flags:
        return [f"Dockerfile: configure flags {docker_flags} differ from .ci/run's {ci_flags}"]
    return []


def check_build_targets(args, runs, build):
    """The image builds only the two binaries it ships and runs no tests: .ci/run ran them
    on the host build, then runs the image itself (tests/deploy/test_image.sh)."""
    problems, targets = [], None
    wanted = sorted(os.path.basename(p) for p in (args.boicpd, args.boicp))
    for stage, argument in runs:
        for words in shell_commands(argument):
            if words[:1] == ["ctest"]:
                problems.append("Dockerfile: no ctest in the image (.ci/run tests the host build)")
            if words[:2] == ["cmake", "--build"] and stage == build:
                if "--target" not in words:
                    problems.append(f"Dockerfile: cmake --build must build only --target {wanted}")
                    continue
                start = words.index("--target") + 1
                targets = sorted(w for w in words[start:] if not w.startswith("-"))
    if targets is not None and targets != wanted:
        problems.append(f"Dockerfile: cmake --build --target {targets}, want {wanted}")
    if targets is None and not problems:
        problems.append("Dockerfile: the build stage has no cmake --build --target line")
    return problems


def check_copied_binaries(args, instructions, stages):
    """The default target copies exactly the binaries CMake builds, from where CMake
    puts them in the build stage; `prebuilt` takes the same files from the build context."""
    built = {}
    for path in (args.boicpd, args.boicp):
        built[os.path.basename(path)] = os.path.relpath(path, args.build_dir)
    prebuilt, runtime = stages.index(("base", "prebuilt")), stages.index(("base", "runtime"))
    copied, context = {}, {}
    for stage, keyword, argument in instructions:
        sources = [w for w in argument.split() if not w.startswith("--")][:-1]
        if keyword == "COPY" and stage == runtime and "--from=build" in argument.split():
            copied.update((os.path.basename(source), source) for source in sources)
        if keyword == "COPY" and stage == prebuilt:
            context.update((os.path.basename(source), source) for source in sources)
    problems = []
    for stage in (prebuilt, runtime):
        if [k for s, k, _ in instructions if s == stage and k != "FROM"] != ["COPY"]:
            problems.append(f"Dockerfile: the {stages[stage][1]} stage must only copy the binaries"
                            " (the rest belongs in base, which both targets share)")
    if set(copied) != set(built):
        problems.append(f"Dockerfile: copies {sorted(copied)}, CMake builds {sorted(built)}")
    for name, source in copied.items():
        if name in built and not source.endswith("/build/" + built[name]):
            problems.append(f"Dockerfile: {source} is not where CMake puts {name} (build/{built[name]})")
        if context.get(name) != "build/" + built.get(name, ""):
            problems.append(f"Dockerfile: the prebuilt stage must copy build/{built.get(name)}")
    return problems


def check_base_stage(instructions, known_env, root, base):
    by_keyword = {}
    for stage, keyword, argument in instructions:
        if stage == base:
            by_keyword.setdefault(keyword, []).append(argument)
    problems = []
    health = by_keyword.get("HEALTHCHECK", [])
    if len(health) != 1 or exec_form(health[0].partition("CMD")[2])[:2] != ["boicp", "health"]:
        problems.append("Dockerfile: the base stage needs one HEALTHCHECK CMD boicp health")
    users = by_keyword.get("USER", [])
    if not users or users[-1].split(":")[0] in ("root", "0"):
        problems.append("Dockerfile: the base stage must end with a non-root USER")
    env = dockerfile_env(by_keyword.get("ENV", []))
    problems += [
        f"Dockerfile: ENV {name} is not a boicpd variable"
        for name in env
        if name.startswith("BOICPD_") and name not in known_env
    ]
    volumes = " ".join(by_keyword.get("VOLUME", []))
    if env.get("BOICPD_DATA_DIR") is None or env["BOICPD_DATA_DIR"] not in volumes:
        problems.append("Dockerfile: VOLUME must hold ENV BOICPD_DATA_DIR")
    port = env.get("BOICPD_LISTEN", "").rpartition(":")[2]
    if not port or port not in " ".join(by_keyword.get("EXPOSE", [])):
        problems.append("Dockerfile: EXPOSE must give BOICPD_LISTEN's port")
    if exec_form((by_keyword.get("CMD") or [""])[-1])[:1] != ["boicpd"]:
        problems.append("Dockerfile: the image's CMD must start boicpd")
    labels = " ".join(by_keyword.get("LABEL", []))
    if "org.opencontainers.image.title" not in labels:
        problems.append("Dockerfile: OCI labels (org.opencontainers.image.*) missing")
    version = re.search(r"ARG VERSION=(\S+)", read(os.path.join(root, "Dockerfile")))
    if not version or version.group(1) != project_version(root):
        problems.append("Dockerfile: ARG VERSION must equal CMake's project VERSION")
    return problems


def dockerfile_env(arguments):
    env = {}
    for argument in arguments:
        for word in shlex.split(argument):
            name, _, value = word.partition("=")
            env[name] = value
    return env


def check_runtime_packages(args):
    """Every library the binaries link directly comes from a --list-runtime package, and
    every such package is linked, so the runtime image neither misses nor carries one."""
    if not (shutil.which("objdump") and shutil.which("dpkg-query") and shutil.which("ldd")):
        print("objdump, ldd or dpkg-query missing: not a Debian build machine")
        return None
    _, runtime = package_lists(args.root)
    libraries, problems = {}, []
    for binary in (args.boicpd, args.boicp):
        listing = run(["ldd", binary])
        resolved = dict(re.findall(r"^\s*(\S+) => (\S+)", listing, re.M))
        # The dynamic loader, which code built position-independent links for
        # thread-local storage, is listed by its path alone.
        for path in re.findall(r"^\s*(/\S+) \(0x", listing, re.M):
            resolved.setdefault(os.path.basename(path), path)
        for library in re.findall(r"^\s*NEEDED\s+(\S+)", run(["objdump", "-p", binary]), re.M):
            if library in resolved:
                libraries[library] = resolved[library]
            else:
                problems.append(f"{binary}: {library} does not resolve")
    owners = owning_packages(libraries.values())
    needed_packages = set()
    for library, path in sorted(libraries.items()):
        if path in owners:
            needed_packages.add(owners[path])
        else:
            problems.append(f"no Debian package owns {path} ({library})")
    problems += [
        f"install-deps.sh --list-runtime lacks {p} (linked by boicpd/boicp)"
        for p in sorted(needed_packages - set(runtime))
    ]
    problems += [
        f"install-deps.sh --list-runtime has {p}, which neither binary links"
        for p in sorted(set(runtime) - needed_packages)
    ]
    return problems


def owning_packages(paths):
    """{path: package} from one dpkg-query call. Debian's merged /usr means dpkg may
    know a library under /lib, /usr/lib, or only by its resolved name."""
    aliases = {}
    for path in paths:
        for candidate in (path, os.path.realpath(path)):
            aliases[candidate] = path
            if candidate.startswith("/usr/lib/"):
                aliases[candidate[len("/usr") :]] = path
    result = subprocess.run(
        ["dpkg-query", "-S", *sorted(aliases)], capture_output=True, text=True
    )  # exits 1 when some alias is unknown; the others are still listed
    owners = {}
    for line in result.stdout.splitlines():
        package, _, candidate = line.partition(": ")
        if candidate in aliases:
            owners[aliases[candidate]] = package.split(":")[0].split(",")[0].strip()
    return owners


def load_yaml_documents(paths):
    import yaml  # python3-yaml, a dependency of yamllint

    documents = []
    for path in paths:
        with open(path, encoding="utf-8") as f:
            documents += [(path, d) for d in yaml.safe_load_all(f) if d]
    return documents


def check_manifests(args):
    root = args.root
    k8s = os.path.join(root, "deploy", "k8s")
    paths = sorted(
        os.path.join(d, f) for d, _, files in os.walk(k8s) for f in files if f.endswith(".yaml")
    )
    docs = load_yaml_documents(paths)
    known_env = {env for env, _ in daemon_env_options(args.boicpd).values()}
    image = "boicp:" + project_version(root)
    uid = re.search(r"--uid (\d+)", read(os.path.join(root, "Dockerfile"))).group(1)
    problems = []
    for path, doc in docs:
        kind = doc.get("kind")
        name = f"{os.path.relpath(path, root)} ({kind})"
        if kind == "Kustomization":
            problems += [
                f"{name}: resource {r} does not exist"
                for r in doc.get("resources", [])
                if not os.path.exists(os.path.join(os.path.dirname(path), r))
            ]
            continue
        pod = pod_spec(doc)
        if pod is None:
            continue
        problems += check_pod(name, pod, image, uid, known_env)
        if pod.get("automountServiceAccountToken") is not False:
            problems.append(f"{name}: automountServiceAccountToken must be false")
        if kind == "Job" and doc["spec"].get("completionMode") == "Indexed":
            problems += check_indexed_job(name, doc)
        if kind == "Deployment":
            problems += check_daemon_pod(name, pod["containers"][0])
    policies = [doc for _, doc in docs if doc.get("kind") == "NetworkPolicy"]
    if not any("boicpd" in str(p.get("spec", {}).get("podSelector")) for p in policies):
        problems.append("deploy/k8s: no NetworkPolicy selects the boicpd pod")
    problems += check_compose(root, image, known_env)
    return problems


def pod_spec(doc):
    return doc.get("spec", {}).get("template", {}).get("spec")


def container_env(container):
    return {e["name"]: e.get("value") for e in container.get("env", [])}


def check_pod(name, pod, image, uid, known_env):
    problems = []
    if str(pod.get("securityContext", {}).get("runAsUser")) != uid:
        problems.append(f"{name}: runAsUser must be the image's uid {uid}")
    for c in pod["containers"]:
        if c.get("image") != image:
            problems.append(f"{name}: image {c.get('image')} is not {image}")
        if "requests" not in c.get("resources", {}):
            problems.append(f"{name}: container {c['name']} has no resource requests")
        problems += [
            f"{name}: env {e} is not a boicpd variable"
            for e in container_env(c)
            if e.startswith("BOICPD_") and e not in known_env
        ]
    return problems


def check_indexed_job(name, doc):
    container = pod_spec(doc)["containers"][0]
    script = " ".join(container.get("command", []) + container.get("args", []))
    problems = []
    if str(container_env(container).get("BOICP_SHARDS")) != str(doc["spec"].get("completions")):
        problems.append(f"{name}: BOICP_SHARDS must equal completions")
    if "JOB_COMPLETION_INDEX + 1" not in script or "--shard" not in script:
        problems.append(f"{name}: the shard must be --shard $((JOB_COMPLETION_INDEX + 1))/N")
    return problems


def check_daemon_pod(name, container):
    env = container_env(container)
    port = env.get("BOICPD_LISTEN", "").rpartition(":")[2]
    problems = []
    ports = [str(p["containerPort"]) for p in container.get("ports", [])]
    if port not in ports:
        problems.append(f"{name}: containerPort must be BOICPD_LISTEN's port {port}")
    # boicpd serves TLS beyond loopback (closed by default), which native
    # grpc probes cannot speak: each probe runs boicp health against it.
    for key in ("BOICPD_AUTH_TOKEN_FILE", "BOICPD_TLS_CERT", "BOICPD_TLS_KEY"):
        if not env.get(key):
            problems.append(f"{name}: {key} must be set (a token, and TLS for it)")
    health = ["boicp", "health", "--server", f"localhost:{port}",
              "--tls-ca", env.get("BOICPD_TLS_CERT")]
    for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
        if container.get(probe, {}).get("exec", {}).get("command") != health:
            problems.append(f"{name}: {probe} must run {' '.join(map(str, health))}")
    cpu = str(container.get("resources", {}).get("requests", {}).get("cpu"))
    if env.get("BOICPD_WORKERS") != cpu:
        problems.append(f"{name}: BOICPD_WORKERS must equal the CPU request ({cpu})")
    return problems


def check_compose(root, image, known_env):
    path = os.path.join(root, "deploy", "docker-compose.yml")
    services = load_yaml_documents([path])[0][1]["services"]
    problems = []
    daemon = services.get("boicpd", {})
    if daemon.get("healthcheck", {}).get("test", [])[1:3] != ["boicp", "health"]:
        problems.append("deploy/docker-compose.yml: boicpd's healthcheck must run boicp health")
    for name, service in services.items():
        if service.get("image") != image:
            problems.append(f"deploy/docker-compose.yml: {name} image is not {image}")
        problems += [
            f"deploy/docker-compose.yml: {name} env {e} is not a boicpd variable"
            for e in service.get("environment", {})
            if e.startswith("BOICPD_") and e not in known_env
        ]
    return problems


def command_words(text, subcommand):
    """The words of the first `exec boicp SUBCOMMAND ...` of a shell script, lines joined."""
    joined = text.replace("\\\n", " ")
    for line in joined.splitlines():
        words = shlex.split(line, comments=True) if not line.lstrip().startswith("#") else []
        if words[:3] == ["exec", "boicp", subcommand]:
            return words[1:]
    return None


def shard_command(words):
    """(scans, out, K, N, {literal flag: value}) of a `boicp map ... --shard K/N` command;
    flags whose value is a variable are the operator's and left out."""
    if not words or words[:2] != ["boicp", "map"] or "--shard" not in words or "-o" not in words:
        return None
    k, _, n = words[words.index("--shard") + 1].rpartition("/")
    fixed, rest = {}, list(words[3:])
    i = 0
    while i < len(rest):
        flag = rest[i]
        value = rest[i + 1] if i + 1 < len(rest) else ""
        if flag in ("-o", "--shard"):
            i += 2
            continue
        if flag.startswith("--") and "$" not in flag and "$" not in value:
            fixed[flag] = value
        i += 2 if flag.startswith("-") else 1
    return words[2], words[words.index("-o") + 1], k, n, fixed


def check_batch_commands(args):
    """The Slurm shard task and the Kubernetes Indexed Job run the same shard command:
    `boicp map SCANS -o OUT --shard K/N` with K 1-based from the scheduler's index, N the
    number of tasks, the same fixed flags; and both merges are `boicp merge OUT -o OUT`."""
    root = args.root
    slurm_dir = os.path.join(root, "deploy", "slurm")
    batch = os.path.join(root, "deploy", "k8s", "batch")
    problems = []
    job = load_yaml_documents([os.path.join(batch, "map-shards-job.yaml")])[0][1]
    container = pod_spec(job)["containers"][0]
    k8s_script = ""
    if container.get("command") == ["sh", "-c"]:
        k8s_script = " ".join(container.get("args", []))
    k8s = shard_command(command_words(k8s_script, "map"))
    slurm = shard_command(command_words(read(os.path.join(slurm_dir, "map-shards.sbatch")), "map"))
    if k8s is None:
        return ["deploy/k8s/batch/map-shards-job.yaml: no `exec boicp map ... -o ... --shard K/N`"]
    if slurm is None:
        return ["deploy/slurm/map-shards.sbatch: no `exec boicp map ... -o ... --shard K/N`"]
    if (k8s[2], k8s[3]) != ("$((JOB_COMPLETION_INDEX + 1))", "${BOICP_SHARDS}"):
        problems.append(f"map-shards-job.yaml: --shard {k8s[2]}/{k8s[3]}, want "
                        "$((JOB_COMPLETION_INDEX + 1))/${BOICP_SHARDS}")
    if (slurm[2], slurm[3]) != ("$((SLURM_ARRAY_TASK_ID))", "$SLURM_ARRAY_TASK_COUNT"):
        problems.append(f"map-shards.sbatch: --shard {slurm[2]}/{slurm[3]}, want "
                        "$((SLURM_ARRAY_TASK_ID))/$SLURM_ARRAY_TASK_COUNT")
    # SLURM_ARRAY_TASK_ID is K itself only when the array is numbered 1..N.
    if '--array="1-$shards"' not in read(os.path.join(slurm_dir, "submit.sh")):
        problems.append('deploy/slurm/submit.sh: the array must be --array="1-$shards"')
    if k8s[4] != slurm[4]:
        problems.append(f"shard flags differ: Kubernetes {k8s[4]}, Slurm {slurm[4]}")
    merge_job = load_yaml_documents([os.path.join(batch, "merge-job.yaml")])[0][1]
    k8s_merge = pod_spec(merge_job)["containers"][0].get("command", [])
    slurm_merge = command_words(read(os.path.join(slurm_dir, "merge.sbatch")), "merge")
    for name, words in (("merge-job.yaml", k8s_merge), ("merge.sbatch", slurm_merge)):
        if not words or len(words) != 5 or words[3] != "-o" or words[2] != words[4]:
            problems.append(f"{name}: the merge must be `boicp merge OUT -o OUT`, got {words}")
    if k8s_merge and k8s_merge[2] != k8s[1]:
        problems.append("merge-job.yaml: merges another folder than the shards' -o")
    if slurm_merge and not (slurm_merge[2] == "$1" and slurm[1] == "$out"):
        problems.append("merge.sbatch: must merge its OUTDIR argument, the shards' -o")
    return problems


def check_readme_table(args):
    """README's Deploy table lists exactly boicpd's flags, their variables and defaults."""
    text = read(os.path.join(args.root, "README.md"))
    section = text.partition("\n## Deploy\n")[2].partition("\n## ")[0]
    if not section:
        return ["README.md: no '## Deploy' section"]
    rows = {}
    for line in section.splitlines():
        m = re.match(r"\|\s*`(--[a-z-]+)`\s*\|\s*`(\w+)`\s*\|([^|]*)\|", line)
        if m:
            rows[m.group(1)] = (m.group(2), m.group(3).strip())
    options = daemon_env_options(args.boicpd)
    problems = []
    for flag in sorted(set(options) | set(rows)):
        if flag not in rows:
            problems.append(f"README.md Deploy table: {flag} missing")
        elif flag not in options:
            problems.append(f"README.md Deploy table: {flag} is not a boicpd flag")
        elif rows[flag][0] != options[flag][0]:
            problems.append(f"README.md Deploy table: {flag} reads {options[flag][0]}")
        else:
            literal = re.fullmatch(r"`([^`]*)`", rows[flag][1])
            if literal and options[flag][1] is not None and literal.group(1) != options[flag][1]:
                problems.append(f"README.md Deploy table: {flag} default is {options[flag][1]}")
    return problems


CHECKS = {
    "dockerfile": check_dockerfile,
    "runtime-packages": check_runtime_packages,
    "manifests": check_manifests,
    "batch-commands": check_batch_commands,
    "readme-table": check_readme_table,
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("check", choices=sorted(CHECKS))
    parser.add_argument("--root", required=True)
    parser.add_argument("--build-dir", required=True)
    parser.add_argument("--boicpd", required=True)
    parser.add_argument("--boicp", required=True)
    args = parser.parse_args()
    problems = CHECKS[args.check](args)
    if problems is None:
        return SKIP
    for problem in problems:
        print(problem)
    print(f"{args.check}: {'ok' if not problems else f'{len(problems)} problem(s)'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
