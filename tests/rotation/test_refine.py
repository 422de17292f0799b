import numpy as np
import pytest

from rotation.refine import solve3


@pytest.mark.parametrize("seed", range(5))
def test_solve3_solves_a_normal_equations_system_as_lapack_does(seed):
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(40, 3)) * [400.0, 400.0, 1.0]  # pitch, yaw in px; roll far weaker
    H, g = J.T @ J, rng.normal(size=3)
    assert np.allclose(solve3(H, g), np.linalg.solve(H, g), rtol=1e-10, atol=0)


def test_solve3_gives_no_step_for_an_ill_posed_system():
    one_direction = np.outer([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])  # rank 1: det 0
    assert np.array_equal(solve3(one_direction, np.ones(3)), np.zeros(3))
    assert np.array_equal(solve3(np.zeros((3, 3)), np.ones(3)), np.zeros(3))
