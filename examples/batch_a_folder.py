"""Plan a folder of scene files in parallel and read the summary.

    python examples/batch_a_folder.py [OUT]

Writes six generated scenes (two of them narrow passages) into OUT/scenes, plans them in
two local processes into OUT/plans, as ``cpr-plan batch OUT/scenes --out OUT/plans`` does.
"""

import sys
from pathlib import Path

from planning import dump_scene
from planning.batch import run_batch, scene_files, summary_csv
from planning.bench.scene_generator import generate_scenes

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/examples/batch")
(out / "scenes").mkdir(parents=True, exist_ok=True)
for scene in generate_scenes(6, seed=4, narrow=2):
    dump_scene(scene, out / "scenes" / f"{scene.name}.yaml")

run = run_batch(scene_files(out / "scenes"), (out / "plans").resolve(), workers=2)
for item in run.items:
    duration = "-" if item.record is None else f"{item.record['duration']:.2f} s"
    print(f"{item.scene:<12} {item.status:<14} {duration}")
(out / "plans" / "summary.csv").write_text(summary_csv(run.items))
print(f"{sum(i.status == 'ok' for i in run.items)}/{len(run.items)} planned")
