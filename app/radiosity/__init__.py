"""Radiosity: patches, form factors (hemicube, ray-cast, analytic), solvers, Gouraud display.

Pure layer: no GL at import. The GPU hemicube (:mod:`app.radiosity.hemicube_gl`) and the GL
image (:mod:`app.radiosity.display_gl`) are imported only when asked for.
"""
