"""Planning many scene files: one isolated task per scene, in local processes or on a Dask cluster.

- :mod:`~planning.batch.items`: a scene's task (:func:`plan_scene_file`, never raises), its
  row (:class:`BatchItem`) and the ``summary.csv`` of the rows;
- :mod:`~planning.batch.pool`: :func:`run_batch`, local processes (loky) that survive a
  crashing scene;
- :mod:`~planning.batch.cluster`: the same on a ``dask.distributed`` cluster.

The process that dispatches the scenes imports none of the planner: each worker does.
"""

from planning.batch.cluster import check_scheduler
from planning.batch.items import BatchItem, plan_scene_file, scene_files, summary_csv
from planning.batch.pool import BatchRun, check_workers, run_batch

__all__ = [
    "BatchItem",
    "BatchRun",
    "check_scheduler",
    "check_workers",
    "plan_scene_file",
    "run_batch",
    "scene_files",
    "summary_csv",
]
