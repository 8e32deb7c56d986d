"""At scale: many views on many workers (``render_many``), multi-view datasets (``render_dataset``).

Importing this package is light: executors import multiprocessing pieces and Ray only when they run.
"""

from frustum.batch.dataset import DEPTH_FORMATS, FORMATS, LAYOUTS, DatasetResult, dataset_cameras, render_dataset
from frustum.batch.executors import EXECUTORS, render_many
from frustum.batch.jobs import OUTPUT_KINDS, RenderJob, ViewResult

__all__ = [
    "DEPTH_FORMATS",
    "EXECUTORS",
    "FORMATS",
    "LAYOUTS",
    "OUTPUT_KINDS",
    "DatasetResult",
    "RenderJob",
    "ViewResult",
    "dataset_cameras",
    "render_dataset",
    "render_many",
]
