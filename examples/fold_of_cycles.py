"""A fold of limit cycles, written as equations: the normal form

    r' = r (mu + 2 r^2 - r^4),   theta' = 1

in Cartesian coordinates (X, Y). Its cycles lie where mu = s^2 - 2 s (s = r^2), period 2 pi:
the outer one stable, the inner one unstable, meeting in a fold at mu = -1, r = 1 (the
multiplier of a cycle is exp(8 pi s (1 - s))). ``tests/test_autonomous.py`` checks the
continuation of these cycles against that closed form.

Run it: ``python examples/fold_of_cycles.py`` (the branch through the fold, printed); on the
command line ``nonsmooth continue --model examples/fold_of_cycles.py:MODEL --param mu
--section Y --crossing increasing --x0 1.5 --direction down --step 0.05 --bounds -1.5 -0.05
--plot fold.png``.
"""

import nonsmooth as ns

MODEL = ns.model_from_equations(
    "fold_of_cycles", states=("X", "Y"), parameters={"mu": -0.5},
    modes={"flow": ["X*(mu + 2*(X**2 + Y**2) - (X**2 + Y**2)**2) - Y",
                    "Y*(mu + 2*(X**2 + Y**2) - (X**2 + Y**2)**2) + X"]}, omega=None)

if __name__ == "__main__":
    p = MODEL.params()
    br = ns.continuation(p, "mu", section=("Y", "increasing"), x0=1.5, direction="down",
                         step=0.05, bounds=(-1.5, -0.05))
    n_stable = int(br.stable.values.sum())
    print(f"{br.sizes['point']} points, {n_stable} stable; "
          f"fold at mu = {float(br.special_mu[0]):.6f}")
