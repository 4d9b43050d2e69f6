"""The chunk store behind --resume, against a hostile or unlucky world: damaged and foreign
chunks, concurrent runs, user errors, planted symbolic links, full disks, SIGTERM and SIGHUP.
Runs that are about processes, files or signals are real `sweep` subprocesses."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import sweep
from sweep.store import ChunkStore

from conftest import stderr_lines, sweep_env


# 63 points, 8 chunks of up to 8: a fraction of a second once the kernels are cached.
SCENE = """
name = "store-test"
[cable]
damping_ratio = 0.02
[load]
amplitude = 4.0
[initial]
displacement = 1e-3
[axes]
length = {start = 0.3, stop = 1.0, num = 9}
frequency_ratio = {start = 0.5, stop = 3.0, num = 7}
[solver]
t_end = 1.0
[run]
threads = 1
chunk_size = 8
"""
N = 63
VOLATILE = {"history", "run_seconds"}


def _env() -> dict:
    return sweep_env()


def _sweep(cwd: Path, *args: str, code: str | None = None,
           timeout: float = 300) -> subprocess.CompletedProcess:
    """`sweep run s.toml -o out.nc --quiet ARGS` in `cwd` (or `code` run before the CLI)."""
    prelude = ["-c", (code or "") + "\nimport sys\nfrom sweep.cli import main\n"
               "sys.exit(main(sys.argv[1:]))"]
    return subprocess.run([sys.executable, *prelude, "run", "s.toml", "-o", "out.nc", "--quiet",
                           *args], cwd=cwd, env=_env(), capture_output=True, text=True,
                          timeout=timeout)


def _same(a_path: Path, b_path: Path) -> None:
    with xr.open_dataset(a_path) as a, xr.open_dataset(b_path) as b:
        assert set(a.variables) == set(b.variables)
        for name in a.variables:
            np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert {k: v for k, v in a.attrs.items() if k not in VOLATILE} == \
            {k: v for k, v in b.attrs.items() if k not in VOLATILE}


@pytest.fixture(scope="module")
def whole(tmp_path_factory) -> Path:
    """The scene run without interruption, by the CLI, as a file."""
    here = tmp_path_factory.mktemp("whole")
    (here / "s.toml").write_text(SCENE)
    done = _sweep(here)
    assert done.returncode == 0, done.stderr
    return here / "out.nc"


# The CLI, but the final write is interrupted: the store is left complete.
KEEP_STORE = ("import importlib\nr = importlib.import_module('sweep.run')\n"
              "def stop(*a, **k): raise KeyboardInterrupt\n"
              "r.write_netcdf = stop\n")


def _complete_store(tmp_path: Path) -> Path:
    (tmp_path / "s.toml").write_text(SCENE)
    left = _sweep(tmp_path, code=KEEP_STORE)
    assert left.returncode == 130, left.stderr
    store = tmp_path / "out.nc.chunks"
    assert len(list(store.glob("chunk-*.npz"))) == 8
    return store


@pytest.mark.slow
def test_damaged_and_foreign_chunks_are_recomputed_in_one_line(tmp_path, whole):
    """Empty, truncated, one flipped byte, a chunk copied over another range, another run's
    chunk and a symbolic link: each is recomputed (one line, no traceback), the link's target
    is left untouched, and the file equals an uninterrupted run's."""
    store = _complete_store(tmp_path)
    chunks = sorted(store.glob("chunk-*.npz"))
    chunks[0].write_bytes(b"")                                        # empty
    chunks[1].write_bytes(chunks[1].read_bytes()[:300])              # truncated
    raw = bytearray(chunks[2].read_bytes())
    with np.load(chunks[2]) as data:                # one flipped bit, inside an array's data
        payload = max((data[k] for k in data.files if not k.startswith("__")),
                      key=lambda a: a.nbytes).tobytes()
    at = bytes(raw).find(payload)
    assert at > 0
    raw[at + len(payload) // 2] ^= 0x01
    chunks[2].write_bytes(bytes(raw))
    chunks[3].write_bytes(chunks[4].read_bytes())                    # another range's
    with np.load(chunks[5]) as data:                                 # another run's
        arrays = {k: data[k] for k in data.files if not k.startswith("__")}
    lo, hi = (int(x) for x in chunks[5].stem.split("-")[1:3])
    ChunkStore(tmp_path / "out.nc", "another run").save(lo, hi, arrays)
    victim = tmp_path / "victim.npz"
    victim.write_bytes(chunks[6].read_bytes())
    before = victim.read_bytes()
    chunks[6].unlink()
    chunks[6].symlink_to(victim)                                      # a planted link
    redone = sum(int(p.stem.split("-")[2]) - int(p.stem.split("-")[1]) for p in chunks[:7]
                 if p != chunks[4])

    done = _sweep(tmp_path, "--resume")
    assert done.returncode == 0, done.stderr
    lines = done.stderr.strip().splitlines()
    assert "Traceback" not in done.stderr
    warning = [line for line in lines if "not used" in line]
    assert len(warning) == 1 and "6 chunk files" in warning[0], done.stderr
    assert f"{redone:,} computed" in done.stderr, done.stderr
    assert victim.read_bytes() == before
    _same(tmp_path / "out.nc", whole)


@pytest.mark.slow
def test_a_second_run_on_a_store_in_use_is_refused_and_a_stale_lock_taken_over(tmp_path,
                                                                             whole):
    """While this process holds the store, a second `sweep run` says one line naming it and
    the pid; once the holder is gone (a lock left holding a dead pid) --resume takes it over."""
    store = _complete_store(tmp_path)
    holder = ChunkStore(tmp_path / "out.nc", "any")
    holder._lock()
    try:
        for args in ((), ("--resume",), ("--overwrite",)):
            busy = _sweep(tmp_path, *args)
            assert busy.returncode == 2, busy.stderr
            assert busy.stderr.strip() == (
                f"sweep: error: out.nc.chunks/ is in use by a running sweep (pid {os.getpid()}); "
                "wait for it to finish, or choose another -o path"), busy.stderr
            assert len(list(store.glob("chunk-*.npz"))) == 8          # nothing touched
    finally:
        holder.release()
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True)
    (store / "lock").write_text(gone.stdout)                          # a dead pid, no lock held
    done = _sweep(tmp_path, "--resume")
    assert done.returncode == 0, done.stderr
    assert f"{N:,} of {N:,} points were already done" in done.stderr
    _same(tmp_path / "out.nc", whole)


def test_a_user_error_after_the_store_was_made_does_not_block_the_same_command(tmp_path,
                                                                              monkeypatch):
    """A run that fails with a user error before finishing a chunk removes its store, so the
    same command runs afterwards; one that fails holding work keeps it for --resume."""
    import importlib
    ex = importlib.import_module("sweep.execute")
    run_module = importlib.import_module("sweep.run")
    scene = sweep.load_scene_text(SCENE)
    out = tmp_path / "out.nc"

    def fails(*args, **kwargs):
        raise sweep.UserError("run.scheduler 'tcp://nowhere:1': no dask scheduler answers")

    with monkeypatch.context() as m:
        m.setattr(ex, "_execute_threads", fails)
        with pytest.raises(sweep.UserError, match="no dask scheduler"):
            sweep.run(scene, output=out, progress=False)
    assert not (tmp_path / "out.nc.chunks").exists()
    sweep.run(scene, output=out, progress=False)                       # not blocked
    assert out.exists() and not (tmp_path / "out.nc.chunks").exists()

    def unwritable(*args, **kwargs):
        raise sweep.UserError("output: could not be written")

    with monkeypatch.context() as m:
        m.setattr(run_module, "write_netcdf", unwritable)
        with pytest.raises(sweep.UserError):
            sweep.run(scene, output=out, overwrite=True, progress=False)
    assert len(list((tmp_path / "out.nc.chunks").glob("chunk-*.npz"))) == 8
    sweep.run(scene, output=out, resume=True, overwrite=True, progress=False)


@pytest.mark.slow
def test_planted_links_are_never_written_through(tmp_path, whole):
    """A link at the old predictable temporary name, a symlinked chunk store and a link at
    OUT.nc itself: every target is left untouched (the link at OUT.nc is replaced by the file);
    a symlinked store is refused in one line."""
    (tmp_path / "s.toml").write_text(SCENE)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    # the old name, for the pids the child may get (the next few)
    probe = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                           capture_output=True, text=True)
    pid = int(probe.stdout)
    for p in range(pid, pid + 50):
        (tmp_path / f".out.nc.{p}.tmp").symlink_to(victim)
    (tmp_path / "out.nc").symlink_to(tmp_path / "elsewhere.nc")       # dangling link at OUT
    done = _sweep(tmp_path)
    assert done.returncode == 0, done.stderr
    assert victim.read_text() == "precious"
    assert not (tmp_path / "elsewhere.nc").exists()
    assert (tmp_path / "out.nc").is_file() and not (tmp_path / "out.nc").is_symlink()
    _same(tmp_path / "out.nc", whole)
    assert all((tmp_path / f".out.nc.{p}.tmp").is_symlink() for p in range(pid, pid + 50))

    target = tmp_path / "their-dir"
    target.mkdir()
    (tmp_path / "out2.nc.chunks").symlink_to(target)
    refused = subprocess.run([sys.executable, "-m", "sweep.cli", "run", "s.toml", "-o",
                              "out2.nc", "--quiet"], cwd=tmp_path, env=_env(),
                             capture_output=True, text=True)
    assert refused.returncode == 2
    assert refused.stderr.strip().splitlines() == [
        f"sweep: error: chunk store 'out2.nc.chunks': is a symbolic link, refused (a sweep "
        "writes only a store it made: remove the link)"], refused.stderr
    assert list(target.iterdir()) == []


def test_stale_temporaries_of_a_killed_write_are_removed_and_only_those(tmp_path):
    """The next run removes a temporary of ours whose process is gone; one of a live process
    and a link of the same name stay."""
    from sweep.io import remove_stale_temporaries
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True)
    dead = int(gone.stdout)
    stale = tmp_path / f".out.nc.{dead}.k3j_x9.tmp"
    older = tmp_path / f".out.nc.{dead}.tmp"
    live = tmp_path / f".out.nc.{os.getpid()}.abc.tmp"
    other = tmp_path / f".other.nc.{dead}.abc.tmp"
    link = tmp_path / f".out.nc.{dead}.lnk.tmp"
    for path in (stale, older, live, other):
        path.write_text("x")
    link.symlink_to(live)
    removed = remove_stale_temporaries(tmp_path / "out.nc")
    assert sorted(removed) == sorted([stale, older])
    assert not stale.exists() and not older.exists()
    assert live.exists() and other.exists() and link.is_symlink()


# --- full disks -----------------------------------------------------------------------------

@pytest.fixture
def small_disk(tmp_path):
    """A 1 MiB tmpfs at tmp_path/disk (root only; skipped where mount is not allowed)."""
    disk = tmp_path / "disk"
    disk.mkdir()
    try:
        mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=1M", "tmpfs", str(disk)],
                                 capture_output=True, text=True)
    except OSError as exc:
        pytest.skip(f"no mount command ({exc})")
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {mounted.stderr.strip()}")
    try:
        yield disk
    finally:
        subprocess.run(["umount", "-l", str(disk)], capture_output=True)


# 63 points x 401 samples x 8 B: about 200 KiB of series per copy.
SERIES = SCENE + "[outputs]\ntime_series = true\nsample_interval = 0.0025\n"
FILL_DISK = ("import os\n"
             "def fill():\n"
             "    fd = os.open('filler', os.O_WRONLY | os.O_CREAT)\n"
             "    try:\n"
             "        while True: os.write(fd, b'x' * 4096)\n"
             "    except OSError: pass\n"
             "    os.close(fd)\n")
WRITE_ON_FULL = FILL_DISK + ("import importlib\nr = importlib.import_module('sweep.run')\n"
                             "real = r.write_netcdf\n"
                             "def write(*a, **k):\n"
                             "    fill()\n"
                             "    return real(*a, **k)\n"
                             "r.write_netcdf = write\n")


def _no_temporaries(disk: Path) -> None:
    left = [p.name for p in disk.rglob(".*") if p.name.endswith(".tmp")]
    assert left == [], left


@pytest.mark.slow
def test_a_full_disk_before_during_chunks_and_during_the_write_is_one_line_and_resumable(
        small_disk, tmp_path):
    disk = small_disk
    (disk / "s.toml").write_text(SERIES)
    (tmp_path / "s.toml").write_text(SERIES)
    reference = _sweep(tmp_path)
    assert reference.returncode == 0, reference.stderr

    # before the run: 20x the points do not fit; refused at once, nothing left
    big = _sweep(disk, "--set", "axes.length={start = 0.3, stop = 1.0, num = 180}")
    assert big.returncode == 2, big.stderr
    line = big.stderr.strip()
    assert len(line.splitlines()) == 1 and "not enough space" in line and "out.nc.chunks" in line
    assert "MiB" in line
    assert sorted(p.name for p in disk.iterdir()) == ["s.toml"]

    # while writing chunks: the disk fills just before the third chunk is saved
    code = (FILL_DISK + "import sweep.store as s\n"
            "real = s.ChunkStore.save\ncalls = []\n"
            "def save(self, lo, hi, arrays):\n"
            "    calls.append(lo)\n"
            "    if len(calls) == 3: fill()\n"
            "    return real(self, lo, hi, arrays)\n"
            "s.ChunkStore.save = save\n")
    chunks = _sweep(disk, code=code)
    assert chunks.returncode == 2, chunks.stderr
    line = chunks.stderr.strip()
    assert len(line.splitlines()) == 1 and "no space left" in line and "--resume" in line, line
    _no_temporaries(disk)
    assert len(list((disk / "out.nc.chunks").glob("chunk-*.npz"))) == 2
    (disk / "filler").unlink()

    # while writing the netCDF file: the chunks stay, the temporary goes
    write = _sweep(disk, "--resume", code=WRITE_ON_FULL)
    assert write.returncode == 2, write.stderr
    line = write.stderr.strip().splitlines()[-1]
    assert "output 'out.nc': no space left" in line and "--resume" in line, write.stderr
    assert "Traceback" not in write.stderr
    _no_temporaries(disk)
    assert not (disk / "out.nc").exists()
    assert len(list((disk / "out.nc.chunks").glob("chunk-*.npz"))) == 8
    (disk / "filler").unlink()

    done = _sweep(disk, "--resume")
    assert done.returncode == 0, done.stderr
    assert f"{N:,} of {N:,} points were already done" in done.stderr
    _same(disk / "out.nc", tmp_path / "out.nc")


# --- SIGTERM, SIGHUP -------------------------------------------------------------------------

LONG_SCENE = SCENE.replace("t_end = 1.0", "t_end = 80.0\nrtol = 1e-10").replace(
    "num = 9", "num = 30").replace(
    "chunk_size = 8", "chunk_size = 1000")
SHORT_BLOCKS = ("import sys, sweep.execute as e, sweep.threads as t; "
                "t.BLOCK_SECONDS = e.FLUSH_SECONDS = 0.2; "
                "from sweep.cli import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_and_sighup_stop_like_ctrl_c(tmp_path, signum):
    """Part-way through a chunk: exit status 128 + signum, one line naming the --resume
    command, the finished blocks kept (and valid: a resume uses them all)."""
    (tmp_path / "s.toml").write_text(LONG_SCENE)
    store = tmp_path / "out.nc.chunks"
    proc = subprocess.Popen([sys.executable, "-c", SHORT_BLOCKS, "run", "s.toml", "-o",
                             "out.nc"], cwd=tmp_path, env=_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not list(store.glob("chunk-*.npz")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.02)
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 128 + signum, err
    lines = stderr_lines(err)
    assert len(lines) == 1 and "Traceback" not in err, err
    assert signal.Signals(signum).name in lines[0]
    assert lines[0].endswith("finish the run with: sweep run s.toml -o out.nc --resume"), err
    assert list(store.glob("chunk-*.npz")) and not list(store.glob(".*.tmp"))


def test_a_signal_during_the_final_write_waits_for_it(ctrl_c_raises):
    """Ctrl-C, SIGTERM or SIGHUP while the finished run is written is held until the file is
    whole (an exception inside xarray's write left its file lock taken: the process hung in
    close), then reported; outside the write the handlers are the caller's again."""
    from sweep.execute import signals_held
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    with signals_held() as held:
        os.kill(os.getpid(), signal.SIGTERM)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)                       # the handlers run between bytecodes
    assert held == [signal.SIGTERM, signal.SIGINT]
    assert {s: signal.getsignal(s) for s in before} == before


@pytest.mark.slow
def test_sigterm_while_writing_finishes_the_file(tmp_path):
    """The run's last phase: SIGTERM sent once the chunk store is complete lands in the write;
    the file is written whole, the store dropped, the process exits at once (not hung)."""
    (tmp_path / "s.toml").write_text(SCENE.replace("chunk_size = 8", "chunk_size = 1000"))
    code = ("import sys, os, signal, sweep.run; r = sys.modules['sweep.run']\n"
            "write = r.write_netcdf\n"
            "def slow(*a, **k):\n"
            "    os.kill(os.getpid(), signal.SIGTERM); import time; time.sleep(0.1)\n"
            "    return write(*a, **k)\n"
            "r.write_netcdf = slow\n"
            "from sweep.cli import main; sys.exit(main(sys.argv[1:]))")
    done = subprocess.run([sys.executable, "-c", code, "run", "s.toml", "-o", "out.nc"],
                          cwd=tmp_path, env=_env(), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "SIGTERM received while writing 'out.nc'" in done.stderr
    assert (tmp_path / "out.nc").exists() and not (tmp_path / "out.nc.chunks").exists()
    _no_temporaries(tmp_path)


def test_a_store_made_by_other_kernels_is_never_resumed(tmp_path, monkeypatch):
    """The run's fingerprint holds the kernels' sources: a store left by other kernels (whose
    outputs may differ in value or layout, e.g. a `reals` column added) is refused on
    --resume in one line, never read into this run's arrays."""
    from sweep import jitcache, runner
    from sweep.errors import UserError
    scene = sweep.load_scene("paper-fig5")
    assert jitcache.package_sources_digest() != ""
    mine = runner.run_fingerprint(scene)
    monkeypatch.setattr(jitcache, "package_sources_digest",
                        lambda package="sweep.kernels": "0" * 64)
    theirs = runner.run_fingerprint(scene)
    assert theirs != mine
    old = ChunkStore(tmp_path / "o.nc", theirs)
    old.open(resume=False, overwrite=False, chunk_size=2)
    old.save(0, 2, {"states": np.zeros(2, np.int8)})
    old.release()
    with pytest.raises(UserError, match="another version of cable-sweep") as refused:
        ChunkStore(tmp_path / "o.nc", mine).open(resume=True, overwrite=False, chunk_size=2)
    assert "\n" not in str(refused.value)


def test_a_full_disk_while_the_store_is_made_leaves_no_store(tmp_path, monkeypatch):
    """The disk full as the store writes its run.json: one line (no '0.0 MiB' estimate: none
    is known yet), and no empty store with its lock left behind (a reviewer found one)."""
    import errno

    def full(self, path, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(ChunkStore, "_write_atomic", full)
    scene = sweep.load_scene_text(SCENE)
    with pytest.raises(sweep.UserError, match="no space left on the device") as caught:
        sweep.run(scene, output=tmp_path / "out.nc", progress=False)
    assert "0.0 MiB" not in str(caught.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_resuming_a_finished_run_says_it_is_complete(tmp_path):
    """--resume on a file whose run finished (no store left): not 'file exists', which reads
    as if the run had to start again."""
    scene = sweep.load_scene_text(SCENE)
    out = tmp_path / "out.nc"
    sweep.run(scene, output=out, progress=False)
    with pytest.raises(sweep.UserError, match="already complete") as caught:
        sweep.run(scene, output=out, resume=True, progress=False)
    assert "--overwrite" in str(caught.value)
    with pytest.raises(sweep.UserError, match="file exists"):
        sweep.run(scene, output=out, progress=False)
    # not for a file that holds something else: another scene's run, or no run at all
    other = sweep.load_scene_text(SCENE.replace("t_end = 1.0", "t_end = 0.9"))
    with pytest.raises(sweep.UserError, match="file exists"):
        sweep.run(other, output=out, resume=True, progress=False)
    junk = tmp_path / "junk.nc"
    junk.write_text("garbage")
    with pytest.raises(sweep.UserError, match="file exists"):
        sweep.run(scene, output=junk, resume=True, progress=False)
