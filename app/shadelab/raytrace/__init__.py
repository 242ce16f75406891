"""CPU ray tracing: acceleration (Embree or a numba BVH), Whitted's recursive tracer, the ray
tree of a pixel, and a reference Monte Carlo path tracer. Pure layer: no GL, no GUI."""

BACKENDS = ("auto", "embree", "bvh")  # ray casting: auto = embree when embreex imports
