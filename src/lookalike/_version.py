"""The one place lookalike's version is written: the package, ``--version``, result headers and pyproject.toml's
metadata read it here."""

__version__ = "0.2.0"
