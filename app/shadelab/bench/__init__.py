"""``shadelab bench``: every benchmark in one package, one module per subject.

``raster`` (the GL renderer against a bare moderngl draw), ``shadows`` (shadow volumes),
``raytrace`` (Whitted and the path tracer against Embree and Mitsuba), ``radiosity``
(error against time), ``viewer`` (the interactive viewer against Polyscope, in a subprocess)
and ``polyscope_viewer`` (the Polyscope side of that comparison). Speed is measured here,
never asserted in a test. See ARCHITECTURE.md.
"""
