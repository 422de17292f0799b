"""The same batch as Ray tasks on a real local Ray instance (2 CPUs)."""

import json

import pytest

from stabilize import Settings
from stabilize.batch import find_jobs, run_batch
from tests.stabilize.helpers import SAMPLE as SAMPLE_DIR

ray = pytest.importorskip("ray", reason="the 'cluster' extra (ray) is not installed")
SAMPLE = SAMPLE_DIR / "clip.mp4"


@pytest.fixture(scope="module")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


def test_ray_batch_has_the_same_manifest_and_resume(local_ray, tmp_path):
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    (src / "a.mp4").write_bytes(SAMPLE.read_bytes())
    (src / "b.mp4").write_bytes(SAMPLE.read_bytes())
    (src / "bad.mp4").write_text("not a video")
    rows = run_batch(find_jobs(src, out), out, Settings(), ray_address="auto")
    assert [r["status"] for r in rows] == ["done", "done", "failed"]
    assert (out / "a.mp4").is_file() and (out / "b.mp4").is_file()
    manifest = json.loads((out / "manifest.json").read_text())
    assert {r["input"]: r["status"] for r in manifest} == {
        "a.mp4": "done",
        "b.mp4": "done",
        "bad.mp4": "failed",
    }
    again = run_batch(find_jobs(src, out), out, Settings(), ray_address="auto")
    assert [r["status"] for r in again] == ["skipped", "skipped", "failed"]
