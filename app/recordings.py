"""Recordings opened from the command line (``facetraj gui speech.wav``, or a folder of recordings
without face data): each synthesized with its labels by the same rules as ``facetraj synth``
(a label file or ``.txt`` beside it, else recognized), one after another once the model is ready."""

from __future__ import annotations

from pathlib import Path

from facetraj_engine.errors import InputError
from facetraj_engine.io.audio import AUDIO_SUFFIXES


def recordings_in(path: Path) -> list[Path]:
    """The recordings ``path`` names: an audio file, or the audio files of a folder that is not
    a corpus (no ``corpus.json``); ``[]`` for a corpus folder or description."""
    path = Path(path)
    if path.is_file() and path.suffix.lower() in AUDIO_SUFFIXES:
        return [path]
    if path.is_dir() and not (path / "corpus.json").is_file():
        found = sorted(p for p in path.iterdir() if p.suffix.lower() in AUDIO_SUFFIXES)
        if not found:
            raise InputError(path, "neither a corpus (no corpus.json) nor a folder of recordings "
                                   "(no .wav or .flac files)")
        return found
    return []


class RecordingQueue:
    """Opens ``paths`` in ``window`` one after another: the first once the model is ready, each
    next once the one before is shown (or failed)."""

    def __init__(self, window, paths: list[Path]):
        self.window = window
        self.pending = list(paths)
        self.waiting_for: str | None = None
        window.state.show_default = False
        window.modelReady.connect(self.next)
        window.utteranceChanged.connect(self._shown)

    def _shown(self, name: str) -> None:
        if self.waiting_for is not None and name.startswith(self.waiting_for):
            self.next()

    def next(self) -> None:
        while self.pending:                  # a file that cannot be read: its error, then the next
            path = self.pending.pop(0)
            self.waiting_for = path.stem
            if self.window.open_audio(path):
                return
        self.waiting_for = None
