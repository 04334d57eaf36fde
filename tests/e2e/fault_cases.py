"""Faults while writing: nothing is lost when a run is killed while it writes, the disk
fills, the output folder is read-only or two runs write the same output at once.

Every case starts from a previous result in the output folder (result.ply and its report) and
runs the fit on an unbroken copy of the project; `run_e2e.py fault --case NAME` runs one. Faults
are injected from outside the product: an LD_PRELOAD shim (fault_shim.c) kills the run in the
middle of writing the PLY's temporary or just before its rename, RLIMIT_FSIZE stands for a full
disk, and a folder without write permission (the run as user nobody when the tests run as root,
who may write anywhere) for a read-only one.
"""
import os
import resource
import subprocess
import time

import e2e_lib as lib

PREVIOUS = {"result.ply": b"ply\nprevious result (stand-in)\n", "result_report.txt": b"previous report\n"}


class Fault:
    def __init__(self, name, what, run):
        self.name, self.what, self.run = name, what, run


def temporaries(out_dir):
    return sorted(f for f in os.listdir(out_dir) if ".tmp" in f)


def previous_intact(out_dir):
    failures = []
    for name, data in PREVIOUS.items():
        path = os.path.join(out_dir, name)
        if not os.path.isfile(path) or open(path, "rb").read() != data:
            failures.append(f"the previous {name} was not kept intact")
    return failures


def f_kill(fault):
    def run(t):
        rc, log = t.run(env={"LD_PRELOAD": t.shim, "VBRDF_FAULT": fault, "VBRDF_FAULT_TARGET": "result"})
        failures = [] if rc != 0 else ["the run was not killed (exit status 0)"]
        failures += previous_intact(t.out_dir)
        left = temporaries(t.out_dir)
        print(f"  after the kill: {sorted(os.listdir(t.out_dir))}")
        if not left:
            failures.append("no temporary left behind: the kill did not happen while writing")
        if failures:
            return failures
        # The next run removes the dead run's temporaries and replaces the previous result.
        rc, log = t.run()
        if rc != 0:
            return [f"the run after the kill failed (exit status {rc})"]
        failures += t.sane_result()
        if temporaries(t.out_dir):
            failures.append(f"temporaries left after the next run: {temporaries(t.out_dir)}")
        if "replaces the existing file" not in log:
            failures.append("the log does not say that the previous result was replaced")
        return failures
    return run


def f_disk_full(t):
    limit = 64 * 1024  # bytes: the report fits, the PLY (~300 KB) does not

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    rc, log = t.run(preexec=small_files)
    failures = [] if rc != 0 else ["exit status 0 although the PLY could not be written"]
    for s in ("Cannot write", "result.ply", "file size limit", "the previous file is unchanged"):
        if s not in log:
            failures.append(f"output does not contain {s!r}")
    failures += previous_intact(t.out_dir)
    if temporaries(t.out_dir):
        failures.append(f"temporaries left behind: {temporaries(t.out_dir)}")
    return failures


def f_readonly_outdir(t):
    os.chmod(t.out_dir, 0o555)
    try:
        rc, log = t.run(as_nobody=os.geteuid() == 0)
    finally:
        os.chmod(t.out_dir, 0o755)
    failures = [] if rc != 0 else ["exit status 0 with a read-only output folder"]
    for s in ("is not writable", "Output PLY", "Nothing was written"):
        if s not in log:
            failures.append(f"output does not contain {s!r}")
    failures += previous_intact(t.out_dir)
    return failures


def f_concurrent(t):
    """Two runs with different settings write result.ply at once (each dawdles 3 s before its
    rename, so their commits overlap): the PLY and the report must be one run's complete pair."""
    env = {"LD_PRELOAD": t.shim, "VBRDF_FAULT": "slow_rename", "VBRDF_FAULT_TARGET": "result", "VBRDF_FAULT_SLEEP": "3"}
    first = t.start(values={"maxIterations": 3}, env=env, tag="a")
    time.sleep(2)
    second = t.start(values={"maxIterations": 40}, env=env, tag="b")
    rcs = [p.wait(timeout=1200) for p in (first, second)]
    failures = [f"run {i} failed (exit status {rc})" for i, rc in enumerate(rcs) if rc != 0]
    if failures:
        return failures
    failures += t.sane_result()
    report = lib.read_text(os.path.join(t.out_dir, "result_report.txt"))
    caps = [c for c in (3, 40) if f"cap of {c} iterations" in report]
    ply = lib.read_ply(os.path.join(t.out_dir, "result.ply")).vertex
    most = int(ply["fit_iterations"].max())
    print(f"  report from the run with cap {caps}; PLY: at most {most} iterations per vertex")
    if len(caps) != 1:
        failures.append("the report is not one run's")
    elif (caps[0] == 3) != (most <= 3):
        failures.append(f"the PLY ({most} iterations at most) and the report (cap {caps[0]}) come from different runs")
    if temporaries(t.out_dir):
        failures.append(f"temporaries left behind: {temporaries(t.out_dir)}")
    return failures


FAULTS = [
    Fault("kill_mid_write", "killed (SIGKILL) with 64 KiB of the PLY written; then the next run",
          f_kill("kill_mid_write")),
    Fault("kill_at_rename", "killed with the PLY and report complete but not yet renamed", f_kill("kill_at_rename")),
    Fault("disk_full", "a file size limit of 64 KiB (RLIMIT_FSIZE, as a full disk)", f_disk_full),
    Fault("readonly_outdir", "an output folder without write permission", f_readonly_outdir),
    Fault("concurrent_writes", "two runs with different settings writing one output at once", f_concurrent),
]

BY_NAME = {f.name: f for f in FAULTS}


class Trial:
    """One fault case's project copy and output folder, and how to run meshlabserver on it."""

    def __init__(self, a, work, mlp, out_dir, shim, write_mlx, check_sane):
        self.a, self.work, self.mlp, self.out_dir, self.shim = a, work, mlp, out_dir, shim
        self.write_mlx, self.check_sane = write_mlx, check_sane
        self.runs = 0

    def _command(self, values, tag):
        mlx = os.path.join(self.work, f"fit_{tag}.mlx")
        self.write_mlx(self.a.mlx, mlx, dict({"outputPly": os.path.join(self.out_dir, "result.ply")}, **values))
        return [self.a.wrapper, "-p", self.mlp, "-s", mlx]

    def start(self, values=None, env=None, tag="run", preexec=None, as_nobody=False):
        cmd = self._command(values or {}, tag)
        if as_nobody:
            cmd = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups", "--"] + cmd
        full_env = dict(os.environ, **(env or {}))
        if as_nobody:
            full_env["HOME"] = "/tmp"
        print("running:", " ".join(cmd), flush=True)
        log = open(os.path.join(self.work, f"meshlabserver_{tag}.log"), "wb")
        return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=full_env, preexec_fn=preexec)

    def run(self, values=None, env=None, preexec=None, as_nobody=False):
        self.runs += 1
        tag = f"run{self.runs}"
        rc = self.start(values, env, tag, preexec, as_nobody).wait(timeout=1200)
        log = open(os.path.join(self.work, f"meshlabserver_{tag}.log"), "rb").read().decode("utf-8", "replace")
        print(f"meshlabserver exit status {rc}")
        print("\n".join(l for l in log.splitlines() if "failed" in l or "Cannot" in l or "WARNING" in l))
        self.last_log = log
        return rc, log

    def sane_result(self):
        return self.check_sane(os.path.join(self.out_dir, "result.ply"))
