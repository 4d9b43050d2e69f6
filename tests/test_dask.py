"""The dask backend in a hostile or unlucky world: a scene cannot choose the cluster, results
from a cluster are checked, a dying cluster or a bad address ends in one line, and dask options
that would be ignored are refused."""

from __future__ import annotations

import os
import select
import socket
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import sweep
import sweep.execute as ex
from sweep.cli import main as sweep_main
from sweep.errors import UserError

from conftest import stderr_lines, sweep_env


TINY = """
name = "dask-test"
[initial]
displacement = 1e-3
[solver]
t_end = 0.2
[axes]
length = [0.5, 0.6, 0.7, 0.8]
"""


def _env() -> dict:
    return sweep_env()


def _one_error_line(stderr: str) -> str:
    lines = stderr_lines(stderr)
    assert len(lines) == 1 and lines[0].startswith("sweep: error: "), stderr
    return lines[0]


# --- the scene cannot choose the cluster ------------------------------------------------------

def test_a_scene_naming_a_scheduler_is_refused_and_nothing_connects(tmp_path, capsys):
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.bind(("127.0.0.1", 0))
    listener.listen(8)
    port = listener.getsockname()[1]
    try:
        scene = tmp_path / "hostile.toml"
        scene.write_text(TINY + f'[run]\nbackend = "dask"\nscheduler = "tcp://127.0.0.1:{port}"\n')
        assert sweep_main(["run", str(scene), "-q", "-o", str(tmp_path / "out.nc")]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert "run.scheduler" in line and "--scheduler" in line
        # a client that connected sits in the listener's backlog: readable at once
        connected, _, _ = select.select([listener], [], [], 0.5)
        assert connected == [], "something connected to the scene's scheduler"
        assert not (tmp_path / "out.nc").exists()
        assert not (tmp_path / "out.nc.chunks").exists()
    finally:
        listener.close()


def test_run_scheduler_is_refused_as_an_override_too():
    with pytest.raises(UserError, match="--scheduler"):
        sweep.load_scene_text(TINY, overrides={"run.scheduler": "tcp://127.0.0.1:8786"})


# --- addresses --------------------------------------------------------------------------------

def test_a_malformed_address_is_one_line_before_any_work(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    out = tmp_path / "out.nc"
    proc = subprocess.run([sys.executable, "-m", "sweep.cli", "run", str(scene), "-o", str(out),
                           "--scheduler", "tcp://h:notaport"], capture_output=True, text=True,
                          env=_env(), timeout=120)
    assert proc.returncode == 2
    assert "--scheduler 'tcp://h:notaport'" in _one_error_line(proc.stderr)
    assert not out.exists() and not out.with_name("out.nc.chunks").exists()


@pytest.mark.parametrize("address", ["http://127.0.0.1:8786", "tcp://127.0.0.1", "tcp://:8786",
                                     "tcp://h:0", "tcp://h:70000", "tcp://h:8786/path",
                                     "tcp://user@h:8786", "127.0.0.1:8786", "\x1b[2J"])
def test_malformed_addresses_are_refused(address, capsys):
    assert sweep_main(["run", "paper-fig5", "-q", "--scheduler", address]) == 2
    line = _one_error_line(capsys.readouterr().err)
    assert line.startswith("sweep: error: --scheduler ") and "\x1b" not in line


@pytest.mark.parametrize("address", ["tcp://10.0.0.5:8786", "tls://scheduler.example:8786",
                                     "tcp://[::1]:8786"])
def test_well_formed_addresses_pass(address):
    assert ex.check_scheduler(address) == address


def test_sweep_run_checks_its_scheduler_argument_before_any_work(tmp_path):
    out = tmp_path / "out.nc"
    with pytest.raises(UserError, match="sweep.run: scheduler 'http://x:1'"):
        sweep.run(sweep.load_scene_text(TINY), out, scheduler="http://x:1", progress=False)
    assert not out.exists() and not out.with_name("out.nc.chunks").exists()


# --- options that would be ignored ------------------------------------------------------------

@pytest.mark.parametrize("flags, words", [
    (["--workers", "2"], "--workers 2: sizes the dask backend's LocalCluster"),
    (["--backend", "threads", "--scheduler", "tcp://127.0.0.1:9"], "--scheduler: runs"),
    (["--set", "run.backend=threads", "--scheduler", "tcp://127.0.0.1:9"], "--scheduler: runs"),
    (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "--workers 2: sizes a LocalCluster"),
])
def test_dask_options_that_would_be_ignored_are_refused(flags, words, tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    out = tmp_path / "out.nc"
    assert sweep_main(["run", str(scene), "-q", "-o", str(out), *flags]) == 2
    assert words in _one_error_line(capsys.readouterr().err)
    assert not out.exists()


# --- results from a cluster are checked -------------------------------------------------------

N_SAMPLES = 3
TRANSVERSE_ARGS = (np.zeros(4), N_SAMPLES, "lanes")


def _good(lo: int, hi: int) -> dict:
    out = ex.transverse_outputs(hi - lo, N_SAMPLES)
    for values in out.values():
        values[...] = 0
    return out


def _with(name: str, value) -> dict:
    arrays = _good(10, 14)
    arrays[name] = value
    return arrays


def test_a_result_that_is_exactly_the_chunks_arrays_passes():
    template = ex.chunk_template(ex.transverse_chunk, TRANSVERSE_ARGS)
    arrays = _good(10, 14)
    assert ex.check_chunk(arrays, 10, 14, template) is arrays
    lk = ex.longitudinal_outputs(2, 5, 3, 11)
    template = ex.chunk_template(ex.longitudinal_chunk, (np.zeros(3), np.zeros(3), 5, 11))
    assert ex.check_chunk(lk, 0, 2, template) is lk


@pytest.mark.parametrize("arrays, words", [
    (None, "is a 'NoneType'"),
    ([np.zeros(4)], "is a 'list'"),
    ({k: v for k, v in _good(10, 14).items() if k != "series"}, "missing ['series']"),
    (_with("evil", np.zeros(4)), "unexpected ['evil']"),
    (_with("states", np.zeros(4)), "'states' is float64 (4,), not int8 (4,)"),
    (_with("states", np.zeros(5, np.int8)), "'states' is int8 (5,), not int8 (4,)"),
    (_with("states", np.zeros(3, np.int8)), "'states' is int8 (3,), not int8 (4,)"),
    (_with("series", np.zeros((4, N_SAMPLES + 1))), "not float64 (4, 3)"),
    (_with("reals", np.zeros(_good(0, 4)["reals"].shape, ">f8")), "'reals' is >f8"),
    (_with("counts", np.zeros(_good(0, 4)["counts"].shape, object)), "'counts' is object"),
    (_with("states", np.ma.zeros(4, np.int8)), "'states' is a 'MaskedArray'"),
    (_with("states", [0, 0, 0, 0]), "'states' is a 'list'"),
])
def test_a_malformed_result_is_refused_in_one_line(arrays, words):
    template = ex.chunk_template(ex.transverse_chunk, TRANSVERSE_ARGS)
    with pytest.raises(ex.ClusterFailed) as info:
        ex.check_chunk(arrays, 10, 14, template)
    assert words in str(info.value) and "chunk 10-14" in str(info.value)
    assert "\n" not in str(info.value)


@pytest.mark.slow
def test_a_malformed_result_stops_the_run_and_nothing_of_it_is_placed(monkeypatch):
    pytest.importorskip("dask.distributed")

    def lying(rows, *args, threads=0):       # by value to the worker (a closure)
        lo, hi = int(rows[0, 0]), int(rows[-1, 0]) + 1
        out = ex.transverse_outputs(hi - lo, N_SAMPLES)
        for values in out.values():
            values[...] = lo
        if lo >= 4:
            out["series"] = np.zeros((hi - lo + 1, N_SAMPLES))     # rows for another range
        return out

    monkeypatch.setattr(ex, "transverse_chunk", lying)
    placed = []
    with pytest.raises(UserError) as info:
        ex.execute(lying, lambda lo, hi: np.arange(lo, hi, dtype=float)[:, None], 8,
                   TRANSVERSE_ARGS, lambda lo, hi, arrays: placed.append((lo, hi, arrays)),
                   chunk_size=2, backend="dask", workers=1)
    message = str(info.value)
    assert message.startswith("dask: the result of chunk ") and "'series'" in message
    assert "\n" not in message and "refused" in message
    assert placed and all(hi <= 4 for _, hi, _ in placed)
    assert all((arrays["states"] == lo).all() for lo, _, arrays in placed)


# --- a dying cluster ---------------------------------------------------------------------------

# The child replaces the transverse chunk function by one that kills the worker process running
# it (defined in __main__, so dask ships it by value), then runs the command line as a user does.
DYING = """
import os
import sys
import threading

import sweep.execute
from sweep.cli import main


def dying(params, *args, **kwargs):
    os._exit(3)


if __name__ == "__main__":
    sweep.execute.transverse_chunk = dying
    sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.slow
def test_a_local_cluster_whose_workers_keep_dying_ends_in_one_line(tmp_path):
    pytest.importorskip("dask.distributed")
    script = tmp_path / "dying.py"
    script.write_text(DYING)
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    # The timeout only stops a hang (before: minutes, and 1 900 lines of tracebacks): a few
    # worker restarts take seconds.
    proc = subprocess.run([sys.executable, str(script), "run", str(scene), "-q",
                           "-o", str(tmp_path / "out.nc"), "--backend", "dask", "--workers", "1",
                           "--chunk-size", "2"], capture_output=True, text=True, env=_env(),
                          cwd=tmp_path, timeout=240)
    assert proc.returncode == 2
    line = _one_error_line(proc.stderr)
    assert "chunk 0-2: the worker running it died 2 times on the LocalCluster" in line
    assert "the run stopped" in line
    assert not (tmp_path / "out.nc").exists()


def test_a_listener_that_never_answers_is_one_line_not_a_hang(tmp_path, capsys, monkeypatch):
    """dask's own connect waits for the handshake without bound; the run must not."""
    pytest.importorskip("dask.distributed")
    monkeypatch.setattr(ex, "CONNECT_SECONDS", 1.0)
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.bind(("127.0.0.1", 0))
    listener.listen(8)
    address = f"tcp://127.0.0.1:{listener.getsockname()[1]}"
    try:
        scene = tmp_path / "s.toml"
        scene.write_text(TINY)
        assert sweep_main(["run", str(scene), "-q", "-o", str(tmp_path / "o.nc"),
                           "--scheduler", address]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert f"dask scheduler '{address}': none answers there" in line
        assert not (tmp_path / "o.nc").exists()
    finally:
        listener.close()


def test_a_dask_run_says_nothing_of_a_busy_dashboard_port(tmp_path):
    """The LocalCluster's scheduler always starts an HTTP server; on its default port, 8787,
    it warned the user "Port 8787 is already in use ... Hosting the HTTP server on port N
    instead" whenever another cluster held it. With 8787 held here (or by someone else: then
    busy all the same), a quiet dask run of a tiny scene writes nothing to stderr."""
    pytest.importorskip("dask.distributed")
    holder = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen(1)
    except OSError:
        pass                                          # in use already: as busy as we need
    scene = tmp_path / "s.toml"
    scene.write_text(TINY)
    try:
        proc = subprocess.run([sys.executable, "-m", "sweep", "run", str(scene), "-q",
                               "-o", str(tmp_path / "out.nc"), "--backend", "dask",
                               "--workers", "1"], capture_output=True, text=True,
                              env=_env(), cwd=tmp_path, timeout=240)
    finally:
        holder.close()
    assert proc.returncode == 0, proc.stderr
    assert stderr_lines(proc.stderr) == [], proc.stderr
    assert (tmp_path / "out.nc").exists()


def _stderr_target() -> str:
    return os.readlink("/proc/self/fd/2")


@pytest.mark.skipif(not Path("/proc/self/fd/2").exists(), reason="needs /proc/self/fd")
def test_the_run_s_own_local_cluster_workers_write_no_stderr():
    """A dying worker and the one its nanny starts while the run stops print tracebacks to the
    stderr they inherit, around the run's one line: the LocalCluster a run starts preloads
    sweep.dask_worker, which points the workers' stderr at os.devnull."""
    with ex._quiet_dask():
        client, cluster = ex._connect(None, 1)
        try:
            target = client.submit(_stderr_target, pure=False).result(timeout=60)
        finally:
            ex._close(client, cluster)
    assert target == os.devnull


def test_a_lost_scheduler_while_waiting_is_one_line_naming_resume(monkeypatch):
    """A killed external scheduler cancels every future: dask's wait() raises
    FuturesCancelledError (seen as a 47-line traceback with a real `dask scheduler` killed
    mid-run). It must end as the run's one line, with the finished chunks kept."""
    distributed = pytest.importorskip("dask.distributed")
    from distributed.client import FuturesCancelledError

    class Client:                       # stands for a connected client: one worker thread
        def submit(self, fn, *args, **kwargs):
            return object()

        def nthreads(self):
            return {"tcp://127.0.0.1:1": 1}

    def lost(futures, timeout=None, return_when=None):
        raise FuturesCancelledError({"scheduler-connection-lost": list(futures)})

    monkeypatch.setattr(distributed, "wait", lost)
    with pytest.raises(ex.ClusterFailed, match="lost the connection to the scheduler at X "
                                                "while waiting for results"):
        ex._run_tasks(Client(), ex.transverse_chunk, lambda lo, hi: None, TRANSVERSE_ARGS,
                      [(0, 2), (2, 4)], None, None, threading.Event(), None,
                      "the scheduler at X")
