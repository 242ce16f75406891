"""ShadeLab: an interactive lab for illumination and shading."""

__version__ = "0.1.0"
