"""The example files the documentation's commands read exist and are what the documentation says they are: the
parking problems of docs/parking.md (example 1's car, thesis Table 9.1, in other slots) and the mecanum-4 log of
docs/batch.md. Before, the pages named short.yaml, long.yaml and log.csv, which no command made and the repository
did not hold; their commands ran nowhere (tests/test_doc_commands.py runs them now)."""

from __future__ import annotations

from pathlib import Path

import pytest

from doc_examples import command_examples
from wmrkit import catalog
from wmrkit.odometry.log_writer import write_log
from wmrkit.odometry.synthetic import TwistProfile, simulate
from wmrkit.parking.problem import load_problem

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(("page", "path"), [("parking.md", "examples/parking/short.yaml"),
                                             ("parking.md", "examples/parking/long.yaml"),
                                             ("batch.md", "examples/logs/mecanum-4.csv")])
def test_a_file_a_documented_command_reads_exists_and_the_command_is_checked(page, path):
    assert (ROOT / path).is_file()
    assert any(path in command.split() for command, _ in command_examples(page))


@pytest.mark.parametrize(("name", "length", "dx2"), [("short", 2.6, 0.9), ("long", 1000.0, 0.7)])
def test_the_parking_examples_are_example_1_in_another_slot(name, length, dx2):
    thesis, example = load_problem("thesis-9.1"), load_problem(str(ROOT / "examples" / "parking" / f"{name}.yaml"))
    assert example.vehicle == thesis.vehicle
    assert (example.space.H, example.space.dx2) == pytest.approx((length, dx2), abs=1e-12)
    assert (example.space.J, example.space.MS, example.space.final_gap) == (thesis.space.J, thesis.space.MS,
                                                                            thesis.space.final_gap)


def test_the_mecanum_log_is_what_docs_batch_md_says_writes_it(tmp_path):
    robot = catalog.load("mecanum-4")
    drive = TwistProfile.from_segments([(4.0, 0.4, 0.0, 0.0), (4.0, 0.0, 0.3, 0.0), (4.0, 0.3, 0.2, 0.25)])
    write_log(tmp_path / "log.csv", simulate(robot, drive, 20.0).log, robot)
    assert (tmp_path / "log.csv").read_text() == (ROOT / "examples" / "logs" / "mecanum-4.csv").read_text()
