# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # The walkthrough in Python
#
# The steps of `docs/walkthrough.md` — select a structure, fit it, validate it on a second
# record, look at its Bode and step responses with their bands — from Python, on the
# walkthrough's records (`examples/walkthrough/`). Every number equals the command line's
# (`jitterid select / fit / validate --json`) on the same files.
#
# Run it as a script (`python examples/python/walkthrough.py [--out DIR] [--small]`) or open it
# as a notebook with jupytext. `--small` (or `JITTERID_EXAMPLE_SMALL=1`) selects among two
# candidates instead of twenty-four, and fits by BCLS instead of the Box–Jenkins criterion, so
# that a debug build runs it in CI in seconds.

# %%
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import matplotlib

if "ipykernel" not in sys.modules:
    matplotlib.use("Agg")  # a script draws into files, without a display
import matplotlib.pyplot as plt
import numpy as np

import jitterid

HERE = Path(__file__).resolve().parent if "__file__" in globals() else Path("examples/python").resolve()
WALK = HERE.parent / "walkthrough"

parser = argparse.ArgumentParser(description="The walkthrough in Python")
parser.add_argument("--out", default="walkthrough-figures", help="directory of the figures")
parser.add_argument("--small", action="store_true", help="two candidates and a BCLS fit (fast)")
args = parser.parse_args([] if "ipykernel" in sys.modules else None)
small = args.small or os.environ.get("JITTERID_EXAMPLE_SMALL") == "1"
out = Path(args.out)
out.mkdir(parents=True, exist_ok=True)

# %% [markdown]
# ## The records
#
# `read_record` gives a data file's columns and its input realisation (`input_t`, `input_u`:
# the random binary input's switch times and levels, from `estimation.input.csv`). A pandas
# DataFrame with columns `t` and `y` (or indexed by `t`) is a record too.

# %%
estimation = jitterid.read_record(WALK / "estimation.csv")
validation = jitterid.read_record(WALK / "validation.csv")
print(f"estimation: {len(estimation['y'])} samples, validation: {len(validation['y'])} samples")

# %% [markdown]
# ## Step 1: select the order and the jitter family

# %%
select_exp = jitterid.Experiment.from_toml(WALK / "select.toml")
if small:
    # Two candidates of the walkthrough's grid: two poles and one zero (the structure step 2
    # fits, with the delay), without jitter and with the two-point family that the full
    # selection ranks first.
    text = select_exp.text.replace('families = ["none", "gaussian", "two-point", "periodic"]',
                                   'families = ["none", "two-point"]')
    text = text.replace("poles = [1, 3]", "poles = [2, 2]").replace("zeros = [0, 1]", "zeros = [1, 1]")
    select_exp = jitterid.Experiment(text, file="select.toml (two candidates)", dir=str(WALK))
selection = jitterid.select(select_exp, estimation, validation=validation)
print(f"{'poles':>5} {'zeros':>5} {'family':<10} {'criterion':>12} {'ranked by':<13} {'validation fit':>14}")
for c in selection.candidates:
    fit_percent = c["validation_fit_percent"]
    print(f"{c['poles']:>5} {c['zeros']:>5} {c['family']:<10} {c['criterion']:>12.4f} {c['ranked_by']:<13} "
          f"{'–' if fit_percent is None else f'{fit_percent:.2f} %':>14}")

# %% [markdown]
# ## Step 2: fit the chosen structure
#
# `model.toml` adds what selection does not model (an input delay, the free response from the
# unknown initial state, AR(1) noise); `init="auto"` starts from the data-driven initializer's
# model, as `jitterid fit --init auto`.

# %%
model_exp = jitterid.Experiment.from_toml(WALK / "model.toml")
method = "bcls" if small else None  # None: the file's method (the Box–Jenkins criterion)
fit = model_exp.fit(estimation, method=method, init="auto")
print(fit)
for name, value, se in zip(fit.names, fit.params, fit.std_errors):
    print(f"  {name:<14} {value:>12.6g} ± {se:.2g}")
system = fit.system
print("fitted system:", system, "input delay:", system.delay)

# %% [markdown]
# ## Step 3: validate on the second record
#
# Fit percents, residual whiteness (Ljung–Box) and cross-correlation with the input, each with
# its p-value and verdict at the level.

# %%
checked = jitterid.validate(model_exp, estimation, validation=validation, fit=fit)  # level 0.01, as the command line
print(checked)
for role in ("estimation", "validation"):
    report = getattr(checked, role)
    w, c = report["whiteness"], report["cross_correlation"]
    print(f"{role:<10} fit {report['fit_percent']:6.2f} %  whiteness p = {w['p_value']:.3g} "
          f"({'pass' if w['passed'] else 'fail'})  cross-correlation p = {c['p_value']:.3g} "
          f"({'pass' if c['passed'] else 'fail'})")

# %% [markdown]
# ## Figures: the records against the model, Bode and step with ±2σ bands

# %%
records = checked.records()
fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=False)
for ax, role in zip(axes, ("estimation", "validation")):
    r = records[role]
    shown = slice(0, 150)  # a readable stretch of the record
    ax.plot(r["t"][shown], r["y"][shown], ".", ms=3, color="0.5", label="samples")
    ax.plot(r["t"][shown], r["expected"][shown], "-", color="tab:blue", label="model, E[y_k]")
    ax.set_title(f"{role} record, fit {getattr(checked, role)['fit_percent']:.1f} %")
    ax.set_xlabel("t (s)")
axes[0].legend(loc="upper right")
fig.tight_layout()
fig.savefig(out / "records.png", dpi=90)

bode = fit.bode()
fig, (mag, phase) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
mag.semilogx(bode["f"], bode["magnitude_db"], color="tab:blue", label=fit.method)
mag.fill_between(bode["f"], bode["magnitude_db_lo"], bode["magnitude_db_hi"], color="tab:blue", alpha=0.25,
                 label="±2σ")
mag.set_ylabel("|G| (dB)")
mag.legend()
phase.semilogx(bode["f"], bode["phase_deg"], color="tab:blue")
phase.fill_between(bode["f"], bode["phase_deg_lo"], bode["phase_deg_hi"], color="tab:blue", alpha=0.25)
phase.set_ylabel("arg G (degrees)")
phase.set_xlabel("f (Hz)")
fig.tight_layout()
fig.savefig(out / "bode.png", dpi=90)

step = fit.step()
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(step["t"], step["value"], color="tab:blue", label="step response")
ax.fill_between(step["t"], step["lo"], step["hi"], color="tab:blue", alpha=0.25, label="±2σ")
ax.set_xlabel("t (s)")
ax.legend()
fig.tight_layout()
fig.savefig(out / "step.png", dpi=90)

w = checked.estimation["whiteness"]
fig, ax = plt.subplots(figsize=(7, 3.5))
ax.stem(w["lags"][1:], w["values"][1:])
ax.axhline(w["bound"], color="k", ls="--")
ax.axhline(-w["bound"], color="k", ls="--")
ax.set_title(f"residual autocorrelation (Ljung–Box p = {w['p_value']:.3g})")
ax.set_xlabel("lag (samples)")
fig.tight_layout()
fig.savefig(out / "whiteness.png", dpi=90)
print(f"figures in {out}: records.png, bode.png, step.png, whiteness.png")

# %% [markdown]
# ## Elsewhere: python-control and SciPy
#
# `System.to_control(pade_order=…)` and `System.to_scipy()` hand the rational part to those
# packages (optional; the delay needs a Padé approximation in python-control and is refused by
# SciPy). The fitted system's frequency response is `system.frequency_response(f)`, `f` in Hz.
