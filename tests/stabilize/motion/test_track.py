"""stabilize.motion.track: where the agreeing vectors lie."""

import numpy as np

from stabilize.motion.track import mean_rows


def test_the_mean_row_weighs_each_grid_row_by_its_agreeing_vectors():
    rows = np.array([10.0, 50.0, 90.0])  # the grid's rows, px, of a 100 px high field
    inliers = np.zeros((3, 3, 4), bool)
    inliers[0, 0, :] = True  # the top row only: (10 + 0.5) / 100
    inliers[1, 0, :1] = True  # one vector at the top, three at the bottom
    inliers[1, 2, :3] = True
    found = mean_rows(inliers, rows, 100)  # the third agreed nowhere: the middle
    assert np.allclose(found, [0.105, (10.5 + 3 * 90.5) / 4 / 100, 0.5])
