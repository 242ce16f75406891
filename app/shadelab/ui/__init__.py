"""The interactive viewer (imgui-bundle): AppState, panels, the GL viewport, offline jobs."""
