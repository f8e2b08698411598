"""The package version (a module of its own, at the bottom layer: every layer may read it)."""

__version__ = "0.1.0"
