"""Export runs as LeRobot v3.0 datasets with a dataset card (`python -m pipeline.dataset --help`)."""

from pipeline.dataset.export import DEFAULT_FPS, DEFAULT_LICENSE, ExportError, Source, experiment_source, export

__all__ = ["DEFAULT_FPS", "DEFAULT_LICENSE", "ExportError", "Source", "experiment_source", "export"]
