"""The ``facetraj`` command: one console command above both packages.

``engine`` (the synthesis engine) and ``app`` (the desktop app and its headless renderers) never
import this package; it imports both. Each subcommand lives in a module of
:mod:`facetraj.commands`, registered in :data:`facetraj.cli.COMMANDS`.

The command makes its matrix products on one BLAS thread (synthesis, training, the evaluation,
the batch's workers, live mode and the app: :mod:`facetraj_engine.threads`), so OpenBLAS is told
so before numpy loads it (unless the environment says otherwise): it then starts no thread per
core that would spin beside the command's own (issue 48).
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
