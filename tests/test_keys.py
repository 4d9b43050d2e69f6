"""`sweep keys` (the scene-key reference generated from the schema), docs/scene-keys.md, and
`sweep --version`."""

from __future__ import annotations

import importlib.metadata
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from sweep import cli, keys, schema

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "scene-keys.md"


def test_committed_page_is_generated_from_the_schema():
    committed = PAGE.read_text(encoding="utf-8") if PAGE.exists() else "(missing)"
    assert committed == keys.markdown(), (
        "docs/scene-keys.md differs from what sweep/schema.py generates: regenerate it with "
        f"`{keys.REGENERATE}` (from the repository root) and commit it")


def _table_rows(page: str) -> dict[str, list[str]]:
    """Rows of the page's key tables, by dotted key: the cells, unescaped."""
    rows = {}
    for line in page.splitlines():
        if line.startswith("| `") and "." in line.split("|")[1]:
            cells = [c.strip().replace("\\|", "|")
                     for c in line.strip("|").replace("\\|", "\0").split("|")]
            cells = [c.replace("\0", "|") for c in cells]
            rows[cells[0].strip("`")] = cells
    return rows


def test_page_lists_every_key_with_a_default_that_reads_back():
    rows = _table_rows(keys.markdown())
    assert sorted(rows) == sorted(schema.BY_DOTTED)
    for dotted, (_, kind, default, units, _allowed, axis, meaning, _accepts) in rows.items():
        key = schema.BY_DOTTED[dotted]
        assert kind == key.kind and units == key.units and meaning
        assert axis.strip("`") == (key.axis or "")
        if key.default is None:
            assert default == ""
        else:   # the default as written is TOML that parses back to the schema's value
            assert tomllib.loads(f"v = {default.strip('`')}")["v"] == key.default, dotted


@pytest.mark.parametrize("value", [1.1e11, 8900.0, 1e-8, 0.375, 5.73e-12, 0.1 + 0.2, 1e300,
                                   1234567.0, -2.5e-7, 0.0])
def test_float_text_is_short_toml_that_reads_back(value):
    text = keys.toml_value(value)
    assert tomllib.loads(f"v = {text}")["v"] == value
    assert isinstance(tomllib.loads(f"v = {text}")["v"], float)
    assert len(text) <= len(repr(value))


def test_allowed_values_in_words():
    assert keys.allowed(schema.BY_DOTTED["solver.courant"]) == "> 0, <= 1"
    assert keys.allowed(schema.BY_DOTTED["solver.intervals"]) == ">= 2"
    assert keys.allowed(schema.BY_DOTTED["model.kind"]) == '"transverse" | "longitudinal"'
    assert keys.allowed(schema.BY_DOTTED["outputs.time_series"]) == "true | false"


def test_cli_keys_prints_every_key(capsys):
    assert cli.main(["keys"]) == 0
    out = capsys.readouterr().out
    heads = [line.split()[0] for line in out.splitlines() if line and not line[0].isspace()]
    assert [h for h in heads if "." in h] == [k.dotted for k in schema.KEYS]
    assert "[axes]" in heads


def test_cli_keys_one_section_and_one_key(capsys):
    assert cli.main(["keys", "solver"]) == 0
    heads = [line.split()[0] for line in capsys.readouterr().out.splitlines()
             if line and not line[0].isspace()]
    assert heads == [k.dotted for k in schema.KEYS if k.section == "solver"]
    assert cli.main(["keys", "solver.courant"]) == 0
    assert capsys.readouterr().out.splitlines()[:2] == [
        "solver.courant  float = 1.0", "    allowed: > 0, <= 1"]


def test_cli_keys_markdown_is_the_page(capsys):
    assert cli.main(["keys", "--markdown"]) == 0
    assert capsys.readouterr().out == keys.markdown()


@pytest.mark.parametrize("argv, words", [(["keys", "solvr"], "no scene section or dotted key 'solvr'"),
                                         (["keys", "solver", "--markdown"], "covers every key")])
def test_cli_keys_bad_argument_is_one_line(capsys, argv, words):
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("sweep: error: ") and words in err


def test_version_is_the_installed_metadata(capsys):
    with pytest.raises(SystemExit) as exit_:
        cli.main(["--version"])
    assert exit_.value.code == 0
    assert capsys.readouterr().out == (
        f"sweep (cable-sweep) {importlib.metadata.version('cable-sweep')}\n")


def test_version_from_a_source_checkout_falls_back_to_the_constant(monkeypatch, capsys):
    def missing(name):
        raise importlib.metadata.PackageNotFoundError(name)
    monkeypatch.setattr(importlib.metadata, "version", missing)
    with pytest.raises(SystemExit):
        cli.main(["--version"])
    assert capsys.readouterr().out == f"sweep (cable-sweep) {cli.VERSION}\n"


def test_version_constant_matches_pyproject():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert cli.VERSION == project["version"], (
        "sweep/version.py VERSION must equal pyproject.toml's [project] version")


def test_version_from_the_command_line():
    done = subprocess.run([sys.executable, "-m", "sweep.cli", "--version"], capture_output=True,
                          text=True, timeout=120, check=True)
    assert done.stdout.startswith("sweep (cable-sweep) ") and done.stderr == ""
