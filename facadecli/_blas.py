"""One BLAS thread: set before numpy is loaded, so import this module first.

The solver's matrices are small (hundreds of rows): BLAS threads gain nothing on them and
spin against each other, and against a city's worker processes, on a busy machine (a
362-equation least squares: 11 ms on one thread, 420 ms on two loaded cores). A value the
user set is kept; child processes (a city's workers) inherit it."""

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")
