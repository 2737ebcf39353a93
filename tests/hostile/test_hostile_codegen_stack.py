"""Generated C on small stacks: the forward model's workspace (A_na, b, x: rows x unknowns doubles) was a local array,
409 KB for 64 double wheels sensing one spin each, 56 KB for 48 fixed wheels sensing three; a controller thread or a
microcontroller task of 32 KiB crashed (SIGSEGV) in the first call. Above codegen.MAX_STACK_WORK it is static now,
and NAME_forward_work takes the caller's buffer (reentrant)."""

from __future__ import annotations

import math
import shutil
import subprocess

import numpy as np
import pytest

from wmrkit import Robot, catalog
from wmrkit.kinematics.codegen import MAX_STACK_WORK, write_code

GCC = shutil.which("gcc")

DRIVER = """\
#include <pthread.h>
#include <stdio.h>
#include "{n}_kinematics.h"
static double sensed[{P}_N_SENSED] = {{{sensed}}};
static double twist[2][3], residual[2];
static int status[2] = {{99, 99}};
static void *run(void *arg)
{{
    static double buffer[{P}_N_WORK]; /* the caller's workspace, off this small stack */
    (void)arg;
    status[0] = {n}_forward(sensed, NULL, twist[0], &residual[0]);
    status[1] = {n}_forward_work(sensed, NULL, twist[1], &residual[1], buffer);
    return NULL;
}}
int main(void)
{{
    pthread_attr_t attr;
    pthread_t thread;
    pthread_attr_init(&attr);
    if (pthread_attr_setstacksize(&attr, 32768) != 0) return 3; /* a small task's stack: 32 KiB */
    if (pthread_create(&thread, &attr, run, NULL) != 0) return 4;
    pthread_join(thread, NULL);
    for (int k = 0; k < 2; ++k)
        printf("%d %.17g %.17g %.17g %.17g\\n", status[k], twist[k][0], twist[k][1], twist[k][2], residual[k]);
    return 0;
}}
"""


def _fixed_ring(n: int, sensed: int) -> Robot:
    """`n` fixed wheels on a 0.5 m ring rolling straight ahead, the first `sensed` sensing their spins: no steering
    angle, so the closed forms cost no symbolic work (1 s for 48 wheels)."""
    return Robot.from_dict({"name": f"ring{n}", "wheels": [
        {"name": f"w{i}", "type": "fixed", "l": 0.5, "alpha": 2 * math.pi * i / n, "heading": 0, "r": 0.1,
         "sensed": ["spin"] if i < sensed else []} for i in range(n)]})


@pytest.mark.skipif(GCC is None, reason="gcc not installed")
def test_the_forward_model_of_many_wheels_runs_on_a_32_kib_stack(tmp_path):
    """48 fixed wheels sensing 3 spins: 96 rows x 48 unknowns, a 57 KB workspace. Before: SIGSEGV (exit -11) in a
    thread of 32 KiB. Now both forward and forward_work answer the least-squares twist and residual (4.11), checked
    against numpy's lstsq of the numeric constraint matrix."""
    robot = _fixed_ring(48, 3)
    header, source = write_code(robot, "c", tmp_path)
    q = np.array([1.0, 2.0, 3.0])
    (tmp_path / "driver.c").write_text(DRIVER.format(n="ring48", P="RING48", sensed=", ".join(map(repr, q.tolist()))))
    exe = tmp_path / "driver"
    subprocess.run([GCC, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe), "driver.c", source.name,
                    "-lm", "-lpthread"], check=True, cwd=tmp_path, capture_output=True, text=True)
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert run.returncode == 0, f"the generated forward model crashed on a 32 KiB stack ({run.returncode})"
    a = robot.constraint_matrix()
    sensed = [robot.velocity_index(f"w{i}.spin") for i in range(3)]
    unknown = [j for j in range(a.shape[1]) if j not in sensed]
    x, *_ = np.linalg.lstsq(a[:, unknown], -a[:, sensed] @ q, rcond=None)
    slip = np.linalg.norm(a[:, unknown] @ x + a[:, sensed] @ q)
    for line in run.stdout.splitlines():  # forward, then forward_work
        status, *twist, residual = line.split()
        assert status == "0"
        np.testing.assert_allclose([float(v) for v in twist], x[:3], rtol=1e-9, atol=1e-12)
        assert float(residual) == pytest.approx(slip, rel=1e-9, abs=1e-12)
    assert "not reentrant" in header.read_text()


def test_a_small_robot_keeps_its_reentrant_workspace_on_the_stack(tmp_path):
    """The forklift's forward model (a few dozen doubles) stays reentrant: its workspace is a local array, and the
    header says so; a robot over MAX_STACK_WORK doubles gets a static one and is told it is not reentrant."""
    header, source = write_code(catalog.load("forklift"), "c", tmp_path)
    n_work = int(next(line.split()[2] for line in header.read_text().splitlines() if "_N_WORK " in line))
    assert n_work <= MAX_STACK_WORK
    assert "    double work[FORKLIFT_N_WORK];" in source.read_text() and "static double work" not in source.read_text()
    assert "on the stack (reentrant)" in header.read_text()
