"""The one place OpenGL contexts, programs and render targets are made (moderngl + PyOpenGL)."""
