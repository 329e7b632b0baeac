"""Bundled scenes (installed from the top-level scenes/ folder)."""
