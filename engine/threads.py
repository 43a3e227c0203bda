"""How many threads numpy's BLAS may use.

OpenBLAS keeps a thread per core and lets idle ones spin while they wait for work. Our matrix
products are small (frames x codewords), so a second BLAS thread buys little, and when the cores
are busy (the evaluation's worker processes, the app's synthesis beside its rendering, other
programs) the spinning threads take the cores from the work: a whole-codebook synthesis measured
0.65 s of CPU with one BLAS thread and 2.2-10.5 s with two, on the 2-core machine under load
(docs/benchmarks.md). Work that runs beside other work therefore uses one BLAS thread.
"""

from __future__ import annotations

from contextlib import AbstractContextManager

from threadpoolctl import threadpool_limits


def one_blas_thread() -> AbstractContextManager:
    """Limit BLAS to one thread: until the end of the ``with`` block, or (called on its own) for
    the rest of the process.

    >>> import numpy as np
    >>> with one_blas_thread():
    ...     float((np.eye(3) @ np.ones(3)).sum())
    3.0
    """
    return threadpool_limits(limits=1, user_api="blas")
