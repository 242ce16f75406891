"""CPU ray tracing: acceleration (Embree or a numba BVH), Whitted's recursive tracer, the ray
tree of a pixel, and a reference Monte Carlo path tracer. Pure layer: no GL, no GUI."""

import os

from shadelab.environment import drop_bad_thread_counts

BACKENDS = ("auto", "embree", "bvh")  # ray casting: auto = embree when embreex imports

# numba's OpenMP threads sleep between the kernels' parallel loops instead of spinning: the
# tracers alternate short loops with Embree queries and Python, and on a machine with few
# cores (shared with other work) spinning threads take the cores from them. Read by the
# OpenMP runtime when numba first starts it; a value already set is kept.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# A thread count of 0 or "abc" would end numba's first parallel kernel in a traceback.
drop_bad_thread_counts()
