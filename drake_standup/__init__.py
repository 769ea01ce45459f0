"""drake_standup: human-assisted iCub stand-up with trajectory advancement, on Drake."""

import os

# One BLAS thread per process unless the user says otherwise, set before numpy loads
# OpenBLAS: the QP's matrices are about 130 x 130, too small for threads to pay, and on a
# busy 2-core machine OpenBLAS's threads spin (the tick's cost assembly measured 4.1 ms
# against 0.07 ms with one thread; docs/performance.md).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
