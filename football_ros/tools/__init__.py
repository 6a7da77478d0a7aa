"""Recorder, figures and the demo."""
