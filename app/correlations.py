"""The browser's lip-correlation columns: the current utterance scored at once, every corpus
utterance in a low-priority background sweep that waits while sound plays (playback first) and
while foreground work runs (the first frame, a synthesis the user asked for).

The scores are kept per synthesis settings: after a change the sweep computes only what it has
not computed for those settings (going back to earlier settings shows their scores at once),
its progress counts what is known, and the scores of other settings stay shown, greyed, until
theirs arrive (the sweep restarted from nothing, with every column blank, after every change)."""

from __future__ import annotations

import logging

from facetraj_engine.config import SynthConfig
from facetraj_engine.evaluation.scores import trajectory_correlations
from facetraj_engine.method.model import Model

from .browser import UtteranceBrowser
from .state import UtteranceView
from .viewer_model import ViewerModel, correlation_sweep
from .workers import Gate, Progress, Task, TaskRunner

log = logging.getLogger(__name__)


class BrowserScores:
    """Fills ``browser``'s score columns; the sweep runs on ``tasks`` and waits on ``idle``."""

    def __init__(self, browser: UtteranceBrowser, tasks: TaskRunner, idle: Gate):
        self.browser = browser
        self.tasks = tasks
        self.idle = idle
        self.task: Task | None = None
        self.enabled = True         # False: no sweep (the utterance shown is still scored)
        self._model: Model | None = None
        self.known: dict[SynthConfig, dict[str, tuple[float, float]]] = {}   # per settings

    @property
    def running(self) -> bool:
        return self.tasks.running(self.task)

    def score(self, view: UtteranceView | None, model: Model | None) -> None:
        """Score the utterance shown (when it has original markers)."""
        if view is None or view.original is None or model is None:
            return
        try:
            c = trajectory_correlations(view.original, view.shown, view.speech, model)
            self.browser.set_scores(view.utterance.name, c["lower_lip"], c["upper_lip"])
        except Exception:
            log.debug("scoring the current utterance failed", exc_info=True)

    def start(self, state: ViewerModel, on_done=None) -> None:
        """(Re)start the sweep of every corpus utterance under the current settings: the scores
        known for them shown at once, the others computed (only cancel the running sweep while
        disabled)."""
        if self.task is not None:
            self.task.cancel()
        if not self.enabled or state.corpus is None or state.model is None:
            return
        if state.model is not self._model:
            self._model, self.known = state.model, {}
        corpus, model, cfg, ids = state.corpus, state.model, state.synth_config, state.correlation_ids()
        known = self.known.setdefault(cfg, {})
        self.browser.show_scores(known)
        todo = [(split, u) for split, u in ids if u not in known]
        if not todo:
            if on_done is not None:
                on_done(None)
            return
        idle, foreground_idle, total = self.idle, self.tasks.foreground_idle, len(ids)

        def work(progress: Progress) -> None:
            def before(k: int, utt_id: str) -> None:
                progress.wait_open(foreground_idle)
                progress.wait_open(idle)
                progress((total - len(todo) + k) / max(total, 1), f"lip correlations: {utt_id}")

            for _k, utt_id, lower, upper in correlation_sweep(model, corpus, todo, cfg, before):
                progress.partial((utt_id, lower, upper))

        def arrived(obj: tuple[str, float, float]) -> None:
            known[obj[0]] = obj[1:]
            self.browser.set_scores(*obj)

        self.task = self.tasks.run(work, on_done, "lip correlations", on_partial=arrived,
                                   background=True)
