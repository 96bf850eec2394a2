"""The paper's Table 2 from Python: 128 records of the second-order system, fitted by BCLS with
the jitter known; prints the means and standard deviations and, when matplotlib is installed,
draws the estimates' histograms and the Bode plot of the truth and of a fit.

    pip install ./python matplotlib
    python examples/python/table2.py [--runs 128] [--out table2.png]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import jitterid

HERE = Path(__file__).resolve().parent
EXPERIMENT = HERE.parent / "experiments" / "table2.toml"
PAPER_MEAN = {"gain": 0.2000, "zero0": -0.5012, "pole0.re": -0.2504, "pole0.im": 0.3001}
PAPER_STD = {"gain": 0.0025, "zero0": 0.0135, "pole0.re": 0.0019, "pole0.im": 0.0029}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=128)
    parser.add_argument("--seed", type=int, default=jitterid.DEFAULT_SEED)
    parser.add_argument("--out", default="table2.png")
    args = parser.parse_args()

    exp = jitterid.Experiment.from_toml(EXPERIMENT)
    # Two shards keep every run's estimates (for the histograms); merged, they are the study.
    shards = [jitterid.montecarlo(exp, runs=args.runs, seed=args.seed, shard=(i, 2)) for i in range(2)]
    study = jitterid.merge(shards)
    estimates = np.vstack([s.estimates for s in shards])
    print(f"{study.converged}/{study.runs} converged in {study.seconds:.2f} s (summed over shards)")
    print(f"{'parameter':<10} {'true':>9} {'mean':>9} {'std':>9} {'paper mean':>11} {'paper std':>10}")
    for i, name in enumerate(study.names):
        print(f"{name:<10} {study.truth[i]:9.4f} {study.mean[i]:9.4f} {study.std[i]:9.4f} "
              f"{PAPER_MEAN[name]:11.4f} {PAPER_STD[name]:10.4f}")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no figures (pip install matplotlib)")
        return
    fig, axes = plt.subplots(2, 3, figsize=(12, 6))
    for i, name in enumerate(study.names):
        ax = axes.flat[i]
        ax.hist(estimates[:, i], bins=20, color="tab:blue", alpha=0.7)
        ax.axvline(study.truth[i], color="k", label="true")
        ax.set_title(name)
    record = exp.simulate(seed=args.seed, run=0)
    fit = exp.fit(record)
    f = np.logspace(-3, np.log10(0.5), 200)
    truth = jitterid.System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2).frequency_response(f)
    fitted = fit.system.frequency_response(f)
    ax = axes.flat[4]
    ax.loglog(f, np.abs(truth), "k", label="true")
    ax.loglog(f, np.abs(fitted), "--", label="BCLS, run 0")
    ax.set_xlabel("f (Hz)")
    ax.set_title("|G(i2πf)|")
    ax.legend()
    ax = axes.flat[5]
    ax.semilogx(f, np.angle(truth, deg=True), "k")
    ax.semilogx(f, np.angle(fitted, deg=True), "--")
    ax.set_xlabel("f (Hz)")
    ax.set_title("arg G (degrees)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
