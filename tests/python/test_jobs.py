"""The farm job files (jobs/slurm, jobs/kubernetes): the Slurm scripts run here as an array job
would run them (SLURM_ARRAY_TASK_ID/COUNT set by hand, no scheduler) on a small spec, merged, and
compared byte for byte with one build; `bash -n` on both; the Kubernetes manifests parsed (PyYAML)
and checked for what an Indexed Job needs. `scripts/slurm-test` (in the full suite) submits the
same scripts to a real one-node Slurm; no Kubernetes API server runs here, so `kubectl apply`
itself is not exercised."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from sf_cli import BIN, ROOT

SPEC = """name = "msd_j"
kind = "ms-diffuse-table"
quantity = "ms-diffuse"
resolution = [5, 4, 2]
paths = 400
albedo_resolution = 3
albedo_paths = 300

[emit]
function = "msd_j"
"""


def files(root: Path) -> dict:
    return {p.relative_to(root): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_slurm_scripts_parse():
    for s in ["shard.sbatch", "merge.sbatch"]:
        subprocess.run(["bash", "-n", str(ROOT / "jobs/slurm" / s)], check=True)


def test_slurm_array_shards_merge_to_one_build(tmp_path):
    (tmp_path / "fits").mkdir()
    (tmp_path / "fits/msd_j.toml").write_text(SPEC)
    env = dict(os.environ, SHADEFIT=str(BIN), FITS="fits", SPECS="msd_j", SHARD_DIR="shards", OUT="merged")
    n = 4
    for k in range(n):
        task = dict(env, SLURM_ARRAY_TASK_ID=str(k), SLURM_ARRAY_TASK_COUNT=str(n), SLURM_ARRAY_TASK_MIN="0",
                    SLURM_ARRAY_TASK_MAX=str(n - 1), SLURM_CPUS_PER_TASK="1")
        subprocess.run(["bash", str(ROOT / "jobs/slurm/shard.sbatch")], cwd=tmp_path, env=task, check=True, capture_output=True)
    assert len(list((tmp_path / "shards").glob("*.shard"))) == n
    subprocess.run(["bash", str(ROOT / "jobs/slurm/merge.sbatch")], cwd=tmp_path, env=env, check=True, capture_output=True)
    subprocess.run([str(BIN), "--fits", "fits", "--generated", "single", "build"], cwd=tmp_path, check=True, capture_output=True)
    assert files(tmp_path / "merged") == files(tmp_path / "single")
    # An array that does not start at 0 is refused (exit 2) before any work.
    bad = dict(env, SLURM_ARRAY_TASK_ID="1", SLURM_ARRAY_TASK_COUNT="4", SLURM_ARRAY_TASK_MIN="1", SLURM_ARRAY_TASK_MAX="4")
    r = subprocess.run(["bash", str(ROOT / "jobs/slurm/shard.sbatch")], cwd=tmp_path, env=bad, capture_output=True)
    assert r.returncode == 2


def test_kubernetes_manifests_are_indexed_jobs():
    yaml = pytest.importorskip("yaml")
    shard = yaml.safe_load((ROOT / "jobs/kubernetes/shard-job.yaml").read_text())
    merge = yaml.safe_load((ROOT / "jobs/kubernetes/merge-job.yaml").read_text())
    for job in [shard, merge]:
        assert job["apiVersion"] == "batch/v1" and job["kind"] == "Job"
        assert job["spec"]["template"]["spec"]["restartPolicy"] == "Never"
    spec = shard["spec"]
    assert spec["completionMode"] == "Indexed"
    c = spec["template"]["spec"]["containers"][0]
    env = {e["name"]: e["value"] for e in c["env"]}
    # N of K/N is the completion count; K is the pod's index.
    assert int(env["SHARDS"]) == spec["completions"]
    assert '--shard "$JOB_COMPLETION_INDEX/$SHARDS"' in c["args"][0]
    assert (ROOT / "jobs/ms_diffuse/fits" / (env["SPECS"] + ".toml")).is_file()
    assert "merge /shards/*.shard" in merge["spec"]["template"]["spec"]["containers"][0]["args"][0]
