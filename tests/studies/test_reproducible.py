"""A study writes the same bytes every time, with any number of workers: ``auto``
decides by counts (its race chooses dop853 for some runs and radau for others here),
and no column holds a clock reading."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import springc
from extremes.cases import MODELS
from springc.studies import StudyOptions, parse_parameter, run_study, summary_path


@pytest.fixture(scope="module")
def cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    folder = tmp_path_factory.mktemp("cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SPRINGC_CACHE_DIR", str(folder))
        yield folder


def test_a_study_is_byte_identical_on_one_and_two_workers(cache: Path,
                                                          tmp_path: Path) -> None:
    source = tmp_path / "extremes.mdl"
    source.write_text(MODELS)
    model = springc.compile_model(source, "StiffPair")
    # uneven walls: k = 1e4 is not stiff (dop853), k = 1e8 and 1e12 race to radau; the
    # race's own runs (error control off: tightening would rerun them to resolve the
    # excited fast mode, a question of tolerance, not of reproducibility)
    options = [StudyOptions((parse_parameter("k=1e4,1e8,1e12"),), fixed=(("k2", 2.0),),
                            workers=workers, error_control="off") for workers in (1, 2, 2)]
    files = [str(tmp_path / f"study{i}.parquet") for i in range(3)]
    studies = [run_study(model, o, f) for o, f in zip(options, files)]
    assert studies[0].summary.column("solver").to_pylist() == ["dop853", "radau", "radau"]
    assert studies[0].summary.column("steps").to_pylist() == [799, 4729, 129]
    first = Path(files[0]).read_bytes(), Path(summary_path(files[0])).read_bytes()
    for other in files[1:]:
        assert (Path(other).read_bytes(), Path(summary_path(other)).read_bytes()) == first
    assert "wall_time" not in pq.read_schema(files[0]).names
