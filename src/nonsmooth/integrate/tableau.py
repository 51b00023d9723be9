"""Butcher tableaus. A Runge-Kutta method is only its coefficient table; the stepping and the
step-size control that use it are written once (``rkstep.py``, ``hybrid.py``)."""

import numpy as np

# Runge-Kutta-Fehlberg 4(5) (Fehlberg 1969), the method of the paper.
RKF45_C = np.array([0.0, 1 / 4, 3 / 8, 12 / 13, 1.0, 1 / 2])
RKF45_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 4, 0.0, 0.0, 0.0, 0.0],
    [3 / 32, 9 / 32, 0.0, 0.0, 0.0],
    [1932 / 2197, -7200 / 2197, 7296 / 2197, 0.0, 0.0],
    [439 / 216, -8.0, 3680 / 513, -845 / 4104, 0.0],
    [-8 / 27, 2.0, -3544 / 2565, 1859 / 4104, -11 / 40],
])
RKF45_B4 = np.array([25 / 216, 0.0, 1408 / 2565, 2197 / 4104, -1 / 5, 0.0])  # order 4
RKF45_B5 = np.array([16 / 135, 0.0, 6656 / 12825, 28561 / 56430, -9 / 50, 2 / 55])  # order 5
RKF45_E = RKF45_B5 - RKF45_B4  # error estimate weights
RKF45_ORDER = 4  # order of the error estimator's lower solution (controller exponent 1/(q+1))
