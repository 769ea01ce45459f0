"""A lab's own plug-ins for drake_standup: an advancement law (laws.py) and a helper
(helpers.py), named in a scenario by entry point (gated, sway) or by module:attribute; and
its data (make_data.py): a pull logged as a force plate would, for human.mode: recorded,
and its chair as a mesh, for chair.file."""

from pathlib import Path

DATA = Path(__file__).parent / "data"
LAB_PULL = DATA / "lab_pull.csv"
LAB_CHAIR = DATA / "lab_chair.obj"
