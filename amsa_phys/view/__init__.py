"""Seeing a run: the renderer shared by the interactive window and the video recorder."""
