"""The raster renderer (moderngl): passes over a Scene into a render target."""
