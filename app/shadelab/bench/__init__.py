"""``shadelab bench``: every benchmark in one package, one module per subject.

``raster`` (the GL renderer against a bare moderngl draw), ``shadows`` (shadow volumes),
``raytrace`` (Whitted and the path tracer against Embree and Mitsuba), ``radiosity``
(error against time), ``viewer`` (the interactive viewer against Polyscope in subprocesses:
cornell and the lecture at 1280x720 and at 1024x768 presenter, a frame's CPU time broken into
its parts, idle frames against scene size, the first frame on a warm cache) and
``polyscope_viewer`` (the Polyscope side of that comparison). ``goals`` holds every goal and
says which were checked, which failed and what could not be measured. Speed is measured here,
never asserted in a test. See ARCHITECTURE.md.
"""
