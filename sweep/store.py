"""The chunk store behind --resume: finished chunks of one run, on disk next to the output."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from pathlib import Path
from typing import Any

import numpy as np

from .errors import UserError

STORE_SUFFIX = ".chunks"


class ChunkStore:
    """Finished chunks of one run, as .npz files in `<output>.chunks/`, written atomically.

    `fingerprint` identifies the run (resolved scene, kernel, chunking); a store made by another
    run is refused rather than mixed in.
    """

    def __init__(self, output: str | os.PathLike, fingerprint: str) -> None:
        out = Path(output)
        self.directory = out.with_name(out.name + STORE_SUFFIX)
        self.fingerprint = fingerprint

    def exists(self) -> bool:
        return self.directory.exists()

    def open(self, resume: bool, overwrite: bool,
             chunk_size: int) -> tuple[dict[tuple[int, int], dict], int]:
        """Prepare the store; return the chunks already finished (only when resuming) and the
        chunk size to use (a resumed run keeps the interrupted run's)."""
        if self.directory.exists() and not resume:
            if not overwrite:
                raise UserError(f"chunk store '{self.directory}': left by an interrupted run "
                                "(use --resume to finish it, or --overwrite to start again)")
            shutil.rmtree(self.directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        meta = self.directory / "run.json"
        if meta.exists():
            stored = json.loads(meta.read_text())
            if stored.get("fingerprint") != self.fingerprint:
                raise UserError(f"chunk store '{self.directory}': made by a different scene "
                                "(remove it, or use --overwrite to start again)")
            chunk_size = int(stored["chunk_size"])
        else:
            tmp = meta.with_suffix(".tmp")
            tmp.write_text(json.dumps({"fingerprint": self.fingerprint, "chunk_size": chunk_size}))
            os.replace(tmp, meta)
        done = {}
        for path in sorted(self.directory.glob("chunk-*.npz")):
            lo, hi = (int(x) for x in path.stem.split("-")[1:3])
            try:
                with np.load(path) as data:
                    done[(lo, hi)] = {k: data[k] for k in data.files}
            except (OSError, ValueError):
                path.unlink(missing_ok=True)         # torn by a kill: compute it again
        for path in self.directory.glob(".chunk-*.tmp.npz"):
            path.unlink(missing_ok=True)
        return done, chunk_size

    def save(self, lo: int, hi: int, arrays: dict[str, np.ndarray]) -> None:
        path = self.directory / f"chunk-{lo:012d}-{hi:012d}.npz"
        tmp = self.directory / f".chunk-{lo:012d}-{hi:012d}.tmp.npz"
        np.savez(tmp, **arrays)
        os.replace(tmp, path)

    def remove(self) -> None:
        shutil.rmtree(self.directory, ignore_errors=True)


def fingerprint(*parts: Any) -> str:
    """A hash of everything that decides a run's chunks and their contents."""
    text = json.dumps([str(p) for p in parts])
    return hashlib.sha256(text.encode()).hexdigest()
