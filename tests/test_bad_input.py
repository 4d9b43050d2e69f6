"""The bad-input corpus: malformed scene files and command lines.

Every case must end with exit status 2 and exactly one line on stderr that starts with
"sweep: error: ", names the key, axis or file (the expected fragments), and ends with a
parenthesised hint saying how to fix the problem; no traceback, nothing on stdout, and no new
or changed file in the working directory (no output file, no temporary file).

Scene files live in tests/data/bad/*.toml. Each begins with one or two comment lines
``# expect: <fragment>``: lowercase fragments the error line must contain. Most cases run
in-process through `sweep.cli.main` (fast); a few run as real processes to show that no
traceback reaches the terminal.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import sweep
from sweep.cli import main

from conftest import sweep_env

CORPUS = Path(__file__).resolve().parent / "data" / "bad"
BAD_SCENES = sorted(CORPUS.glob("*.toml"))
PREFIX = "sweep: error: "

# A hint says how to fix the problem: it uses one of these words...
FIX_WORDS = re.compile(r"\b(use|give|write|set|remove|choose|check|create|keep|sort|fix|run|"
                       r"save|put|leave|see|did you mean)\b", re.IGNORECASE)
# ...or, for the two longitudinal messages whose text tests/test_scene.py pins exactly, the
# message names the only values allowed ("takes only 'constant'", "it sweeps length, ...").
NAMES_ALLOWED = re.compile(r"takes only '|\(it sweeps ")

# A small, fast valid run (one point, 0.5 s) for the cases that must succeed.
QUICK = ["--set", "axes.length=[0.5]", "--set", "solver.t_end=0.5", "--quiet"]


# --------------------------------------------------------------------------- helpers


def expectations(path: Path) -> list[str]:
    """The ``# expect:`` fragments at the top of a corpus file."""
    found = []
    for line in path.read_bytes().decode("utf-8", errors="replace").splitlines():
        if not line.startswith("# expect:"):
            break
        found.append(line.partition(":")[2].strip())
    return found


def trailing_hint(line: str) -> str:
    """The parenthesised text that ends the line (nested parentheses allowed), or ''."""
    if not line.endswith(")"):
        return ""
    depth = 0
    for index in range(len(line) - 1, -1, -1):
        depth += {")": 1, "(": -1}.get(line[index], 0)
        if depth == 0:
            return line[index + 1:-1]
    return ""


def snapshot(directory: Path) -> dict[str, bytes | None]:
    """Every entry under `directory` (hidden ones too) -> its bytes, None for folders."""
    entries: dict[str, bytes | None] = {}
    for path in sorted(directory.rglob("*")):
        rel = str(path.relative_to(directory))
        if path.is_dir():
            entries[rel] = None
        elif not path.is_file():        # a FIFO fixture: reading it would block
            entries[rel] = b"<special>"
        else:
            try:
                entries[rel] = path.read_bytes()
            except OSError:             # an unreadable fixture: its name is enough
                entries[rel] = b"<unreadable>"
    return entries


def call_main(argv: list[str]) -> int:
    """sweep.cli.main(argv); an argparse error (SystemExit) gives its code."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def assert_user_error(code: int, out: str, err: str, fragments: list[str]) -> str:
    """Exit status 2, nothing on stdout, one fixable line on stderr holding every fragment."""
    assert code == 2, (code, err)
    assert "Traceback" not in err and "Traceback" not in out, err
    assert out == "", out
    lines = err.splitlines()
    assert len(lines) == 1 and err.endswith("\n"), err
    line = lines[0].strip()
    assert line.startswith(PREFIX) and len(line) > len(PREFIX), line
    for fragment in fragments:
        assert fragment.lower() in line.lower(), (fragment, line)
    hint = trailing_hint(line)
    assert hint, f"no '(how to fix it)' at the end: {line}"
    assert FIX_WORDS.search(hint) or NAMES_ALLOWED.search(line), f"hint says no fix: {line}"
    return line


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """An empty working directory (the test's scene fixtures go beside it, not in it)."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    return work


def run_in_process(argv: list[str], fragments: list[str], work: Path, capsys) -> str:
    before = snapshot(work)
    capsys.readouterr()
    code = call_main(argv)
    captured = capsys.readouterr()
    line = assert_user_error(code, captured.out, captured.err, fragments)
    assert snapshot(work) == before, "the working directory changed"
    return line


def run_process(argv: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = sweep_env()
    return subprocess.run([sys.executable, "-m", "sweep.cli", *argv], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=300)


# --------------------------------------------------------------------------- the corpus


def test_corpus_is_complete():
    assert len(BAD_SCENES) >= 35
    for path in BAD_SCENES:
        fragments = expectations(path)
        assert 1 <= len(fragments) <= 2, path.name
        assert all(f and f == f.lower() for f in fragments), path.name
    names = {p.stem for p in BAD_SCENES}
    assert sum(name.startswith("long_") for name in names) >= 8      # both model kinds
    assert len(CLI_CASES) >= 10


@pytest.mark.parametrize("path", BAD_SCENES, ids=[p.stem for p in BAD_SCENES])
def test_bad_scene_file(path, workdir, capsys):
    run_in_process(["run", str(path), "-o", "out.nc"], expectations(path), workdir, capsys)


@pytest.mark.parametrize("data", [b'name = "caf\xe9"\n', b"\xff\xfen\x00a\x00m\x00e\x00"],
                         ids=["latin-1", "utf-16"])
def test_non_utf8_scene_file(data, tmp_path, workdir, capsys):
    path = tmp_path / "encoded.toml"
    path.write_bytes(data)
    run_in_process(["run", str(path), "-o", "out.nc"], ["encoded.toml", "utf-8"], workdir,
                   capsys)


def test_toml_syntax_error_gives_line(workdir, capsys):
    line = run_in_process(["run", str(CORPUS / "toml_syntax_error.toml"), "-o", "out.nc"],
                          [], workdir, capsys)
    assert re.search(r"\bline 6\b", line), line


# --------------------------------------------------------------------------- command lines


def _mkdir(name: str):
    return lambda work: (work / name).mkdir()


def _existing(name: str, data: bytes = b"keep me"):
    return lambda work: (work / name).write_bytes(data)


def _unreadable(work: Path) -> None:
    path = work / "locked.toml"
    path.write_text('name = "locked"\n')
    path.chmod(0)
    try:
        path.read_bytes()
    except PermissionError:
        return
    pytest.skip("file modes do not stop reads here (root); see the /proc/self/mem case")


def _read_only_dir(work: Path) -> None:
    (work / "ro").mkdir()
    (work / "ro").chmod(0o555)
    try:
        (work / "ro" / "probe").touch()
    except PermissionError:
        return
    pytest.skip("directory modes do not stop writes here (root); see the /proc case")


def _proc_mem(work: Path) -> None:
    try:
        Path("/proc/self/mem").read_bytes()
    except OSError:
        return
    pytest.skip("/proc/self/mem is readable here")


def _proc_writable(work: Path) -> None:
    if not Path("/proc").is_dir():
        pytest.skip("no /proc")


def _dev_zero(work: Path) -> None:
    if not Path("/dev/zero").exists():
        pytest.skip("no /dev/zero")


# (id, argv, expected fragments, setup run in the working directory before the snapshot)
CLI_CASES = [
    ("unknown-builtin", ["run", "paper-fig6", "-o", "out.nc"],
     ["scene 'paper-fig6'", "sweep scenes"], None),
    ("empty-scene-name", ["run", "", "-o", "out.nc"], ["scene ''"], None),
    ("missing-file", ["run", "missing.toml", "-o", "out.nc"],
     ["missing.toml", "no such file"], None),
    ("missing-file-in-missing-dir", ["run", "nodir/scene.toml", "-o", "out.nc"],
     ["nodir/scene.toml", "no such file"], None),
    ("directory-as-scene", ["run", "adir", "-o", "out.nc"], ["adir", "directory"],
     _mkdir("adir")),
    ("unreadable-file", ["run", "locked.toml", "-o", "out.nc"],
     ["locked.toml", "cannot be read"], _unreadable),
    ("unreadable-file-proc", ["run", "/proc/self/mem", "-o", "out.nc"],
     ["/proc/self/mem", "cannot be read"], _proc_mem),
    ("endless-file", ["run", "/dev/zero", "-o", "out.nc"], ["/dev/zero", "not a regular file"],
     _dev_zero),
    ("set-without-equals", ["run", "paper-fig5", "-o", "out.nc", "--set", "solver.rtol"],
     ["solver.rtol", "key=value"], None),
    ("set-without-key", ["run", "paper-fig5", "-o", "out.nc", "--set", "=1e-9"],
     ["'=1e-9'", "key=value"], None),
    ("set-unknown-key", ["run", "paper-fig5", "-o", "out.nc", "--set", "cable.lenght=1"],
     ["cable.lenght", "did you mean 'cable.length'"], None),
    ("set-unknown-section", ["run", "paper-fig5", "-o", "out.nc", "--set", "solvr.rtol=1e-9"],
     ["solvr", "did you mean"], None),
    ("set-bad-value", ["run", "paper-fig5", "-o", "out.nc", "--set", "solver.rtol=abc"],
     ["solver.rtol", "number"], None),
    ("set-out-of-range", ["run", "paper-fig5", "-o", "out.nc", "--set", "solver.t_end=-1"],
     ["solver.t_end"], None),
    ("set-nan", ["run", "paper-fig5", "-o", "out.nc", "--set", "load.amplitude=nan"],
     ["load.amplitude", "finite"], None),
    ("set-bad-axis", ["run", "paper-fig5", "-o", "out.nc", "--set", "axes.length=[0.5, 0.5]"],
     ["axis 'length'", "strictly"], None),
    ("set-axis-not-sweepable", ["run", "paper-fig5", "-o", "out.nc",
                                "--set", "axes.rtol=[1e-6, 1e-8]"],
     ["solver.rtol", "cannot be swept"], None),
    ("set-axis-paper-density", ["run", "paper-fig5", "-o", "out.nc",
                                "--set", "axes.density=[8000, 8900]"],
     ["axis 'density'", "paper"], None),
    ("set-both-frequencies", ["run", "paper-fig5", "-o", "out.nc",
                              "--set", "load.frequency=3", "--set", "load.frequency_ratio=2"],
     ["load.frequency", "load.frequency_ratio"], None),
    ("set-courant-above-one", ["run", "paper-fig7", "-o", "out.nc",
                               "--set", "solver.courant=1.5"], ["solver.courant"], None),
    ("output-missing-dir", ["run", "paper-fig5", "-o", "no/such/dir/out.nc"],
     ["no/such/dir", "does not exist"], None),
    ("output-read-only-proc", ["run", "paper-fig5", "-o", "/proc/cable-sweep-test.nc"],
     ["/proc/cable-sweep-test.nc", "not writable"], _proc_writable),
    ("output-read-only-dir", ["run", "paper-fig5", "-o", "ro/out.nc"],
     ["ro/out.nc", "not writable"], _read_only_dir),
    ("output-exists", ["run", "paper-fig5", "-o", "exists.nc"], ["exists.nc", "--overwrite"],
     _existing("exists.nc")),
    ("output-is-directory", ["run", "paper-fig5", "-o", "adir.nc"], ["adir.nc", "directory"],
     _mkdir("adir.nc")),
    ("output-not-nc", ["run", "paper-fig5", "-o", "out.txt"], ["out.txt", ".nc"], None),
    ("output-empty", ["run", "paper-fig5", "-o", ""], ["output ''", "empty"], None),
    ("output-trailing-slash", ["run", "paper-fig5", "-o", "out.nc/"],
     ["out.nc/", "directory"], None),
    ("output-only-suffix", ["run", "paper-fig5", "-o", ".nc"], ["'.nc'", "nothing before"],
     None),
    ("output-missing-value", ["run", "paper-fig5", "-o"], ["-o"], None),
    ("threads-zero", ["run", "paper-fig5", "-o", "out.nc", "--threads", "0"],
     ["--threads 0"], None),
    ("threads-negative", ["run", "paper-fig5", "-o", "out.nc", "--threads", "-2"],
     ["--threads -2"], None),
    ("threads-not-a-number", ["run", "paper-fig5", "-o", "out.nc", "--threads", "two"],
     ["--threads", "'two'"], None),
    ("set-list-not-toml", ["run", "paper-fig5", "-o", "out.nc",
                           "--set", "axes.length=[200 mm, 300 mm]"],
     ["'axes.length'", "not a valid toml list"], None),
    ("set-list-unclosed", ["run", "paper-fig5", "-o", "out.nc", "--set", "axes.length=[0.3, 0.5"],
     ["'axes.length'", "not a valid toml list"], None),
    ("result-as-scene", ["run", "result.nc", "-o", "out.nc"], ["result.nc", "netcdf"],
     _existing("result.nc", b"\x89HDF\r\n\x1a\n" + bytes(64))),
    ("unknown-subcommand", ["fly"], ["'fly'", "choose from"], None),
    ("run-without-scene", ["run"], ["scene", "usage"], None),
    ("no-subcommand", [], ["command", "usage"], None),
    ("unknown-option", ["run", "paper-fig5", "-o", "out.nc", "--bogus"], ["--bogus"], None),
    ("scenes-extra-argument", ["scenes", "extra"], ["extra"], None),
    # the resolution is checked before the result is read
    ("plot-dpi-huge", ["plot", "paper-fig5.nc", "--dpi", "1e6"], ["--dpi 1e+06", "2400"],
     None),
]


@pytest.mark.parametrize("argv, fragments, setup", [c[1:] for c in CLI_CASES],
                         ids=[c[0] for c in CLI_CASES])
def test_bad_command_line(argv, fragments, setup, workdir, capsys):
    try:
        if setup is not None:
            setup(workdir)
        run_in_process(argv, fragments, workdir, capsys)
    finally:
        for path in workdir.rglob("*"):        # let pytest clean up chmod'ed fixtures
            path.chmod(0o755 if path.is_dir() else 0o644)


def test_a_sweep_too_large_for_memory_is_one_line(workdir, capsys, monkeypatch):
    """MemoryError (a grid or a field that cannot be allocated) is a user error, not a crash."""
    def too_big(*args, **kwargs):
        raise MemoryError((10**14, 11))
    monkeypatch.setattr(sys.modules["sweep.run"], "run", too_big)
    run_in_process(["run", "paper-fig5", "-o", "out.nc"], ["memory", "axis points"], workdir,
                   capsys)


# --------------------------------------------------------------------------- what must work


def test_existing_output_replaced_with_overwrite(workdir, capsys):
    (workdir / "exists.nc").write_text("keep me")
    run_in_process(["run", "paper-fig5", "-o", "exists.nc", *QUICK], ["--overwrite"],
                   workdir, capsys)
    assert (workdir / "exists.nc").read_text() == "keep me"
    assert call_main(["run", "paper-fig5", "-o", "exists.nc", "--overwrite", *QUICK]) == 0
    assert (workdir / "exists.nc").read_bytes()[:4] == b"\x89HDF"     # netCDF-4
    assert sorted(p.name for p in workdir.iterdir()) == ["exists.nc"]  # no temp file left


def test_scene_text_is_data_never_code(tmp_path, workdir, capsys):
    """Strings that look like Python are names, not code: loading and running executes
    nothing."""
    code = "__import__('os').system('touch PWNED')"
    path = tmp_path / "code.toml"
    path.write_text(f'name = "{code}"\ndescription = "{code}"\n'
                    f"[load]\ntype = \"constant\"\n", encoding="utf-8")
    scene = sweep.load_scene(path)
    assert scene.name == code and scene.description == code
    assert call_main(["run", str(path), "-o", "out.nc", *QUICK,
                      "--set", f"description={code}"]) == 0
    import xarray as xr
    with xr.open_dataset(workdir / "out.nc") as ds:
        assert ds.attrs["title"] == code
    assert not list(tmp_path.rglob("PWNED")) and not Path("PWNED").exists()
    assert sorted(p.name for p in workdir.iterdir()) == ["out.nc"]


# --------------------------------------------------------------------------- real processes


@pytest.mark.parametrize("argv", [
    ["run", str(CORPUS / "toml_syntax_error.toml"), "-o", "out.nc"],
    ["run", str(CORPUS / "long_courant_above_one.toml"), "-o", "out.nc"],
    ["run", "paper-fig5", "-o", "no/such/dir/out.nc"],
    ["run", "paper-fig5", "--set", "cable.lenght=1", "-o", "out.nc"],
    ["fly"],
], ids=["toml-syntax", "courant", "output-missing-dir", "set-typo", "unknown-subcommand"])
def test_process_exits_2_with_one_line_and_no_traceback(argv, workdir):
    r = run_process(argv, workdir)
    assert_user_error(r.returncode, r.stdout, r.stderr, [])
    assert list(workdir.iterdir()) == []


# --------------------------------------------------------------------------- hostile inputs


def test_error_line_escapes_terminal_codes_and_shortens_long_keys(tmp_path, workdir, capsys):
    """A key holding ESC [2J (clear screen) and a 1 MB key are printed escaped and cut short."""
    escape = tmp_path / "escape.toml"
    escape.write_text('[cable]\n"\\u001b[2Jx" = 1\n', encoding="utf-8")
    line = run_in_process(["run", str(escape)], ["unknown key"], workdir, capsys)
    assert "\x1b" not in line and "'cable.\\x1b[2Jx'" in line, line
    huge = tmp_path / "huge-key.toml"
    huge.write_text("[cable]\n" + "k" * 10**6 + " = 1\n", encoding="utf-8")
    line = run_in_process(["run", str(huge)], ["unknown key", "1,000,006 characters"],
                          workdir, capsys)
    assert len(line) < 600, len(line)


def test_override_value_with_control_characters_is_escaped(workdir, capsys):
    line = run_in_process(["run", "paper-fig5", "--set", "solver.method=\x1b]0;pwned\x07"],
                          ["solver.method"], workdir, capsys)
    assert "\x1b" not in line and "\x07" not in line and "\\x1b]0;pwned\\x07" in line, line


def _fifo(work: Path) -> None:
    os.mkfifo(work / "pipe.toml")


def _sparse_file(work: Path) -> None:
    with open(work / "big.toml", "wb") as handle:       # 9 MiB of NULs, no disk blocks
        handle.truncate(9 * 2**20)


def _plain_file(work: Path) -> None:
    (work / "afile").write_text("not a directory")


def _unsearchable_dir(work: Path) -> None:
    (work / "locked").mkdir()
    (work / "locked" / "scene.toml").write_text('name = "x"\n')
    (work / "locked").chmod(0)
    try:
        (work / "locked" / "scene.toml").stat()
    except PermissionError:
        return
    pytest.skip("directory modes do not stop lookups here (root)")


LONG_NAME = "n" * 300        # longer than NAME_MAX (255) on every common file system

# (id, argv, expected fragments, setup): the OS refuses these paths; each is one line.
PATH_CASES = [
    ("scene-name-too-long", ["run", LONG_NAME + ".toml", "-o", "out.nc"],
     ["scene file", "too long"], None),
    ("scene-under-a-file", ["run", "afile/scene.toml", "-o", "out.nc"],
     ["afile/scene.toml", "no such file"], _plain_file),
    ("scene-fifo", ["run", "pipe.toml", "-o", "out.nc"], ["pipe.toml", "fifo"], _fifo),
    ("scene-too-large", ["run", "big.toml", "-o", "out.nc"], ["big.toml", "larger than 8 mib"],
     _sparse_file),
    ("scene-unsearchable-dir", ["run", "locked/scene.toml", "-o", "out.nc"],
     ["locked/scene.toml", "permission denied"], _unsearchable_dir),
    ("output-name-too-long", ["run", "paper-fig5", "-o", LONG_NAME + ".nc"],
     ["output", "too long"], None),
]


@pytest.mark.parametrize("argv, fragments, setup", [c[1:] for c in PATH_CASES],
                         ids=[c[0] for c in PATH_CASES])
def test_os_errors_of_paths_are_one_line(argv, fragments, setup, workdir, capsys):
    try:
        if setup is not None:
            setup(workdir)
        run_in_process(argv, fragments, workdir, capsys)
    finally:
        for path in [workdir, *workdir.iterdir()]:
            if path.is_dir():
                path.chmod(0o755)


def test_fifo_scene_does_not_block_the_process(workdir):
    """A FIFO nobody writes to used to block the read forever: a real process ends at once."""
    os.mkfifo(workdir / "pipe.toml")
    r = run_process(["run", "pipe.toml", "-o", "out.nc"], workdir)
    assert_user_error(r.returncode, r.stdout, r.stderr, ["pipe.toml", "fifo"])
    assert sorted(p.name for p in workdir.iterdir()) == ["pipe.toml"]


def run_process_bytes(argv: list[bytes], cwd: Path) -> subprocess.CompletedProcess:
    """run_process with raw bytes arguments (not valid UTF-8), output decoded leniently."""
    env = sweep_env()
    r = subprocess.run([sys.executable.encode(), b"-m", b"sweep.cli", *argv],
                       capture_output=True, cwd=cwd, env=env, timeout=300)
    return subprocess.CompletedProcess(r.args, r.returncode, r.stdout.decode("utf-8", "replace"),
                                       r.stderr.decode("utf-8", "replace"))


@pytest.mark.parametrize("argv, fragments", [
    ([b"run", b"paper-fig5", b"-o", b"out\xff.nc"], ["output 'out\\udcff.nc'", "utf-8"]),
    ([b"run", b"paper-fig5", b"--set", b"name=caf\xe9", b"-o", b"out.nc"],
     ["scene key 'name'", "utf-8"]),
    ([b"run", b"paper-fig5", b"--set", b"description=\xff", b"-o", b"out.nc"],
     ["scene key 'description'", "utf-8"]),
], ids=["output-name", "scene-name", "description"])
def test_names_netcdf_cannot_store_are_refused_before_the_run(argv, fragments, workdir):
    """Undecodable bytes in -o or in text stored as an attribute used to fail in the netCDF
    write after the whole sweep had run; now the run does not start."""
    r = run_process_bytes(argv, workdir)
    assert_user_error(r.returncode, r.stdout, r.stderr, fragments)
    assert list(workdir.iterdir()) == []


def test_scene_file_whose_name_is_not_utf8_is_refused(tmp_path, workdir):
    name = os.fsencode(tmp_path) + b"/sc\xff.toml"
    with open(name, "wb") as handle:
        handle.write(b'[solver]\nt_end = 0.5\n')
    r = run_process_bytes([b"run", name, b"-o", b"out.nc"], workdir)
    assert_user_error(r.returncode, r.stdout, r.stderr, ["sc\\udcff.toml", "utf-8"])
    assert list(workdir.iterdir()) == []


@pytest.mark.parametrize("text, fragments", [
    ("[cable]\nlength = " + "1" * 4301 + "\n", ["more than 4300 digits"]),
    ("[cable]\nlength = " + "[" * 3000 + "]" * 3000 + "\n", ["nested too deeply"]),
    ("[run]\nthreads = 1" + "0" * 400 + "\n", ["run.threads", "at most"]),
    ("[cable]\ndensity = 5e-324\n", ["cable.density", "k0 = inf"]),
], ids=["digits", "nesting", "int-overflow", "denormal-density"])
def test_process_refuses_parser_classes_in_one_line(text, fragments, tmp_path, workdir):
    path = tmp_path / "scene.toml"
    path.write_text(text, encoding="utf-8")
    r = run_process(["run", str(path), "-o", "out.nc"], workdir)
    assert_user_error(r.returncode, r.stdout, r.stderr, fragments)
    assert list(workdir.iterdir()) == []


@pytest.mark.parametrize("name, expected", [
    ("out\udcff.nc", "not valid UTF-8"),
    ("x" * 5000 + ".nc", "cannot be checked"),
    ("a\0b.nc", "NUL"),
])
def test_api_output_names_are_checked_before_the_run(tmp_path, name, expected):
    """sweep.run(scene, output=...) refuses an unwritable name before computing, as the CLI
    does (it used to fail in the netCDF write after the whole sweep had run)."""
    from sweep.io import check_output_path
    with pytest.raises(sweep.UserError, match=expected):
        check_output_path(str(tmp_path / name) if "\0" not in name else name)


def test_output_under_a_file_says_it_is_a_file(tmp_path):
    (tmp_path / "afile").write_text("x")
    from sweep.io import check_output_path
    with pytest.raises(sweep.UserError, match="is a file, not a directory"):
        check_output_path(tmp_path / "afile" / "x.nc")


def test_a_scene_name_with_terminal_codes_is_escaped_in_the_summary(workdir, capsys):
    """The summary line quotes the scene's name as the error lines do: escaped, never raw."""
    assert main(["run", "paper-fig5", "-o", "out.nc", "--set", "name=fig\x1b[2J5",
                 "--set", "solver.t_end=0.05"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "fig\\x1b[2J5: 4 points" in out, out


def test_a_long_path_in_an_error_line_keeps_its_file_name(tmp_path, workdir, capsys):
    """A path longer than the line quotes whole is cut in its middle: the file name at its end
    stays readable (a deep temporary folder once hid it)."""
    deep = tmp_path.joinpath(*(["a-rather-long-folder-name"] * 6))
    deep.mkdir(parents=True)
    scene = deep / "the-scene-saved-as-latin-1.toml"
    scene.write_bytes("name = 'caf\u00e9'\n".encode("latin-1"))
    line = run_in_process(["run", str(scene)], ["the-scene-saved-as-latin-1.toml", "UTF-8",
                                                 "characters)"], workdir, capsys)
    assert len(line) < 400, line
