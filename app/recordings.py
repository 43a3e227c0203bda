"""Recordings opened from the command line (``facetraj gui speech.wav``, or a folder of recordings
without face data): each synthesized with its labels by the same rules as ``facetraj synth``
(a label file or ``.txt`` beside it, else recognized), one after another once the model is ready,
the first shown."""

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
    """Opens ``paths`` in ``window``, one after another once the model is ready (at once if it
    is): the first is shown, the others only listed in the browser's "opened" group (each
    labelled in turn, the next once the one before is done or failed), so that the window lands
    on the first (it showed each in turn and ended on the last). Done, it lets go of the window."""

    def __init__(self, window, paths: list[Path]):
        self.window = window
        self.pending = list(paths)
        self.shown = False
        if not window.state.ready:  # the coming model's first utterance is not shown: these are
            window.state.show_default = False
        window.audio_opener.finished.connect(self._done)
        window.when_model_ready(self.next)

    def _done(self, _path: str, ok: bool) -> None:
        self.shown |= ok
        self.next()

    def next(self) -> None:
        if self.pending:             # a file that cannot be read: its error (finished), the next
            self.window.open_audio(self.pending.pop(0), show=not self.shown)
            return
        try:
            self.window.audio_opener.finished.disconnect(self._done)
        except TypeError:              # done already
            pass
