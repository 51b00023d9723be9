"""Independent closed forms used as test oracles (plain numpy, no package code)."""

import numpy as np


def linear_solution(k, c, F, omega, b, X0, V0, t):
    """Solution of X'' + c X' + k X = F cos(omega t) + b with X(0)=X0, X'(0)=V0 (underdamped,
    c^2 < 4k). Returns (X(t), V(t))."""
    t = np.asarray(t, dtype=float)
    den = (k - omega**2) ** 2 + (c * omega) ** 2
    Ac = F * (k - omega**2) / den  # particular: Ac cos + As sin + b/k
    As = F * c * omega / den
    xs = b / k
    mu = c / 2
    wd = np.sqrt(k - mu**2)
    x0h = X0 - (Ac + xs)
    v0h = V0 - As * omega
    c1 = x0h
    c2 = (v0h + mu * c1) / wd
    e = np.exp(-mu * t)
    xh = e * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t))
    vh = e * (-mu * (c1 * np.cos(wd * t) + c2 * np.sin(wd * t)) + wd * (-c1 * np.sin(wd * t) + c2 * np.cos(wd * t)))
    X = Ac * np.cos(omega * t) + As * np.sin(omega * t) + xs + xh
    V = -Ac * omega * np.sin(omega * t) + As * omega * np.cos(omega * t) + vh
    return X, V


def steady_amplitude(omega0, xi, F0, omega):
    return F0 / np.sqrt((omega0**2 - omega**2) ** 2 + (xi * omega) ** 2)
