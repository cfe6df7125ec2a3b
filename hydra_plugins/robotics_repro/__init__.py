"""Hydra plugins of this project: Hydra looks for them under `hydra_plugins` (and, for an editable install, through
the `hydra.plugins` entry point in pyproject.toml)."""
