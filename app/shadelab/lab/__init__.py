"""The viewer's logic without its GUI: state and its sub-states, undo history, the autosaved
session, lessons, the GPU request queue, the frame recorder, the probe, camera control.

Pure package: numpy and the pure layers only, no GL, no imgui. ``ui/`` draws it; the API and
the CLI may import it. See ARCHITECTURE.md §1.
"""
