"""A sweep written as a Slurm array job for a cluster (--slurm;
docs/sessions.md "Sweeps"): the batch script and the command that reruns
what is missing."""
import os
import shlex

from .common import BUILD, ROOT, LabError, replacing
from .sweep_cells import CELL


def write_slurm(sweep_dir, cells, cache_dir, rerun, cell_args=""):
    """A Slurm array job: task N runs cell N of cells.tsv and stores its
    result in the cache; `scripts/lab sweep ... --cached-only` afterwards
    makes the table from the cache. cell_args: scripts/sweep-cell's mode
    before the manifest ("--fly": a closed-loop sweep's cells)."""
    if any(c.isspace() for c in sweep_dir + cache_dir + ROOT + BUILD):
        raise LabError("--slurm: the sweep's folder, the cache and the tree must have no spaces in their "
                       "paths (#SBATCH lines cannot quote them)")
    script = os.path.join(sweep_dir, "sweep.sbatch")
    manifest = os.path.join(sweep_dir, "cells.tsv")
    with replacing(script) as f:
        f.write(f"""#!/bin/sh
# A Slurm array job of {len(cells)} cells (docs/sessions.md "Sweeps"), written by scripts/lab sweep --slurm.
#   sbatch {shlex.quote(script)}
# then, when it has run, the table (every cell from the cache, nothing run here):
#   {rerun}
#SBATCH --job-name=rmslab-sweep
#SBATCH --array=1-{len(cells)}
#SBATCH --cpus-per-task=1
#SBATCH --output={os.path.join(sweep_dir, 'slurm-%A_%a.out')}
export RMSLAB_BUILD={shlex.quote(BUILD)}
exec {shlex.quote(CELL)} {cell_args + " " if cell_args else ""}{shlex.quote(manifest)} \\
  "$SLURM_ARRAY_TASK_ID" --store {shlex.quote(cache_dir)}
""")
    os.chmod(script, 0o755)
    return script


def rerun_command(a, sessions, sweep_dir, cache_dir):
    """The command that makes the table from the cache: absolute paths, every option spelled out."""
    argv = [os.path.join(ROOT, "scripts", "lab"), "sweep"] + [s.path for s in sessions]
    for k, vals in a.grid:
        argv += ["--vary", f"{k}={','.join(vals)}"]
    argv += ["--out", sweep_dir, "--cache", cache_dir, "--cached-only", "--no-build"]
    return " ".join(shlex.quote(x) for x in argv)
