"""graspsim.batch: graspsim jobs over many objects on Ray (docs/batch.md; the client's "batch" extra).

    from graspsim.batch import plan_grasp_database, read_dataset
    summary = plan_grasp_database(["mug.stl", "can.obj"], ["schunk_pg70", "schunk_sdh2"], out_dir="db")
    table = read_dataset(summary.dataset)          # pyarrow.Table, one row per grasp

Every worker is a ServerActor: a Ray actor with a graspsim-server of its own (loopback, its own data dir) and a
graspsim.Client of it. A task whose worker dies is run again on another; finished tasks are skipped when the job
is run again. Importing graspsim does not import Ray; importing graspsim.batch does.
"""
from graspsim.batch._dataset import read_dataset
from graspsim.batch._grasp_db import SCHEMA as GRASP_SCHEMA, load_mesh, mesh_sha256, plan_grasp_database, task_key
from graspsim.batch._map import TaskError, map_scenes
from graspsim.batch._pool import init_ray
from graspsim.batch._server import ServerActor, ServerHost
from graspsim.batch._shapes import SCHEMA as SHAPE_SCHEMA, complete_shapes
from graspsim.batch._summary import BatchSummary

__all__ = ["BatchSummary", "GRASP_SCHEMA", "SHAPE_SCHEMA", "ServerActor", "ServerHost", "TaskError",
           "complete_shapes", "init_ray", "load_mesh", "map_scenes", "mesh_sha256", "plan_grasp_database",
           "read_dataset", "task_key"]
