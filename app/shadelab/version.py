"""ShadeLab's version, in one place: a leaf module (imports nothing), so any layer may read it
without importing the package (``shadelab.__version__`` re-exports it; hatch reads it here)."""

__version__ = "0.1.0"
