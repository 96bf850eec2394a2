"""jitterid: system identification when the sampling instants are noisy (sampling jitter).

The command line's experiments, from Python, with NumPy arrays in and out::

    import jitterid
    exp = jitterid.Experiment.from_toml("examples/experiments/table2.toml")
    record = exp.simulate(seed=1, run=0)          # dict: t, y, u, input_t, input_u
    fit = exp.fit(record, method="bcls")           # FitResult: names, params, std_errors, ...
    study = jitterid.montecarlo(exp, runs=128, seed=1)
    study.mean, study.std
    fit.bode(), fit.step(), fit.system.to_control()   # responses with ±2σ bands; the System
    checked = jitterid.validate(exp, record, validation=exp.simulate(seed=1, run=1))
    checked.fit_percent, checked.whiteness["p_value"]
    jitterid.select(exp_with_a_select_section, record).best

Records may also be pandas DataFrames or Series and xarray objects (``t`` a column or the
index). Every number equals the command line's (``jitterid simulate / fit / validate / select /
montecarlo --json``) for the same seed and run. Jitter models by name or class are in ``jitterid.jitter``. Studies split
into shards (``shard=(i, n)``) run anywhere, for example on Dask, and ``merge`` joins them.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, Iterable, Mapping, Optional, Tuple, Union

import numpy as np

from . import _jitterid, inputs, jitter, system
from ._spec import integer, real_array, real_number
from .inputs import Input
from .system import System
from ._records import as_record
from .results import DesignResult, FitResult, MonteCarloResult, SelectionResult, ValidationResult

#: What the functions take as a record: a mapping of arrays (as ``simulate`` returns), a pandas
#: DataFrame or Series, or an xarray Dataset or DataArray.
Record = Any

__version__: str = _jitterid.__version__
DEFAULT_SEED = 20_051_205

__all__ = [
    "DesignResult",
    "Experiment",
    "FitResult",
    "MonteCarloResult",
    "SelectionResult",
    "ValidationResult",
    "DEFAULT_SEED",
    "Input",
    "System",
    "design",
    "first_moment",
    "fit",
    "inputs",
    "second_moment",
    "simulate",
    "system",
    "jitter",
    "merge",
    "montecarlo",
    "read_record",
    "select",
    "validate",
]


class Experiment(_jitterid.Experiment):
    """An experiment in the command line's TOML format (see ``docs/experiments.md``).

    ``Experiment.from_toml(path)`` reads a file; ``Experiment(text)`` takes the TOML text.
    Experiments pickle by their text.

    A file the experiment names (``[input] path``) is resolved against the experiment file's
    directory (for ``Experiment(text)``: ``dir``, the current directory by default) and must be
    inside it: an absolute path, a ``..`` component or a symbolic link leading out raises
    ``ValueError`` before the file is read, unless ``allow_paths_outside=True`` (keyword only,
    in both constructors; kept when pickled).
    """

    def fit(self, record: Record, method: Optional[str] = None, *, init: str = "experiment",
            progress: Optional[Callable[[int, float], Any]] = None) -> FitResult:
        """Fits ``record`` with ``method`` (``"ls"``, ``"bcls"``, ``"bj"``, ``"ml"``, …; the
        file's by default). The same result as ``jitterid fit --json [--init]``.

        ``record`` is a mapping with ``y`` (and for a random-binary input the ``input_t``,
        ``input_u`` that ``simulate`` and ``read_record`` give), a pandas DataFrame with a
        column ``y`` or a Series of the samples, or an xarray Dataset or DataArray; its sample
        times (a column ``t``, else a pandas index or an xarray coordinate that is not the
        default row numbers) must be the experiment's grid ``start + k·interval``, as a data
        file's ``t`` column must.

        ``init`` is where the search starts: ``"experiment"`` (the file's values),
        ``"auto"`` (the data-driven initializer's rational model, as ``--init auto``; the
        experiment's jitter, noise, delay and initial state kept) or ``"experiment-only"``
        (the file's values, also as a likelihood fit's only start).

        The fit runs without the GIL. ``progress``, if given, is called as
        ``progress(iteration, cost)`` after the solver's start and each of its iterations, on
        the calling thread. Ctrl-C, or an exception raised by ``progress``, stops the solver
        before its next iteration (Levenberg–Marquardt and BFGS; other solvers run to their
        end) and is raised; a ``KeyboardInterrupt``'s ``__cause__`` says where the fit stopped.
        """
        r = as_record(record)
        return FitResult._of(self.fit_record(r["y"], r.get("input_t"), r.get("input_u"), _method(method),
                                             r.get("t"), progress, _init(init)))


def _method(method: Any) -> Optional[str]:
    if method is not None and not isinstance(method, str):
        raise TypeError(f"method: expected the name of a method such as 'bcls', found {type(method).__name__}")
    return method


def _init(init: Any) -> str:
    if not isinstance(init, str):
        raise TypeError(f"init: expected 'experiment', 'auto' or 'experiment-only', found {type(init).__name__}")
    return init


def _experiment(experiment: Any) -> None:
    if not isinstance(experiment, _jitterid.Experiment):
        raise TypeError(f"experiment: expected an Experiment (Experiment.from_toml(path)), found "
                        f"{type(experiment).__name__}")


def validate(experiment: Experiment, record: Record, *, validation: Optional[Record] = None,
             fit: Optional[FitResult] = None, level: float = 0.01,
             method: Optional[str] = None) -> ValidationResult:
    """Validates ``experiment``'s model on ``record`` and, when given, on the ``validation``
    record, as ``jitterid validate --json [--validation] [--model] [--level]``.

    * ``record``, ``validation``: records as ``Experiment.fit`` takes them (a mapping, a
      pandas DataFrame or Series, an xarray Dataset or DataArray; with the input realisation
      ``input_t``, ``input_u`` for a random-binary experiment). The validation record has the
      experiment's interval, its own length (at least 16 samples) and start (its first ``t``;
      the experiment's start without ``t``).
    * ``fit``: the model to validate, a ``FitResult`` (as ``--model`` reads a ``fit --json``
      output, with ``--method`` its method); without it, the experiment's model is fitted to
      ``record`` with ``method`` (the file's by default).
    * ``level``: the level of the residual tests' verdicts, strictly between 0 and 1.

    Returns a ``ValidationResult``: fit percents, the residual tests (statistics, p-values,
    verdicts at ``level``), flatness, and the system's Bode and step responses with ±2σ bands.
    """
    _experiment(experiment)
    r = as_record(record)
    v = None if validation is None else as_record(validation, "validation")
    if fit is not None and not isinstance(fit, FitResult):
        raise TypeError(f"fit: expected a FitResult (the result of a fit) or None, found {type(fit).__name__}")
    validated = _jitterid.validate(
        experiment, r["y"], r.get("input_t"), r.get("input_u"), r.get("t"),
        None if v is None else v["y"], None if v is None else v.get("t"),
        None if v is None else v.get("input_t"), None if v is None else v.get("input_u"),
        None if fit is None else json.dumps(fit.to_dict()), real_number(level, "level"),
        # A given fit is read as the structure of its own method.
        _method(fit.method if method is None and fit is not None else method))
    return ValidationResult(validated)


def _write_record(path: str, record: Dict[str, Any], name: str) -> None:
    """Writes ``record``'s samples as a data file (column ``y``) and, when it has one, its input
    realisation as the side file ``<name>.input.csv``, as ``jitterid simulate`` writes them:
    floats in their shortest round-trip form, which the reader reads back exactly."""
    y = real_array(record["y"], f"{name}['y']")
    if y.ndim != 1:
        raise ValueError(f"{name}['y']: expected a one-dimensional array, found shape {y.shape}")
    rows = [y.tolist()]
    if record.get("t") is not None:
        # Checked by the reader against the experiment's grid, as a data file's `t` is.
        t = real_array(record["t"], f"{name}['t']")
        if t.shape != y.shape:
            raise ValueError(f"{name}['t']: has shape {t.shape}, expected {y.shape} (one time per sample of y)")
        rows.insert(0, t.tolist())
    with open(path, "w") as out:
        out.write(("t,y" if len(rows) == 2 else "y") + "\n")
        out.write("".join(",".join(repr(v) for v in row) + "\n" for row in zip(*rows)))
    if record.get("input_t") is not None:
        t = real_array(record["input_t"], f"{name}['input_t']").ravel()
        levels = record.get("input_u")
        # Several inputs: one column of levels per input, by name, as `simulate` writes them.
        columns = dict(levels) if isinstance(levels, Mapping) else {"u": levels}
        rows = [t.tolist()]
        for column, u in columns.items():
            u = real_array(u, f"{name}['input_u']" + ("" if column == "u" else f"[{column!r}]")).ravel()
            if t.size != u.size:
                raise ValueError(f"{name}['input_t'] and {name}['input_u']: expected equal lengths, found {t.size} "
                                 f"and {u.size}")
            rows.append(u.tolist())
        with open(path[: -len(".csv")] + ".input.csv", "w") as out:
            out.write(",".join(["t", *map(str, columns)]) + "\n")
            out.write("".join(",".join(repr(v) for v in row) + "\n" for row in zip(*rows)))


def select(experiment: Experiment, record: Record, *, validation: Optional[Record] = None,
           time_limit: Optional[float] = None) -> SelectionResult:
    """Selects among ``experiment``'s ``[select]`` grid of model orders and jitter families on
    ``record`` (as ``Experiment.fit`` takes it), with each candidate's fit percent on the
    ``validation`` record when given, within ``time_limit`` seconds (the experiment's
    ``[estimate] max_seconds`` by default, else 600): ``jitterid select --json
    [--validation] [--time-limit]``. Returns a ``SelectionResult`` (candidates ranked best
    first).
    """
    import tempfile

    _experiment(experiment)
    r = as_record(record)
    v = None if validation is None else as_record(validation, "validation")
    limit = None if time_limit is None else real_number(time_limit, "time_limit")
    for name, rec in (("record", r), ("validation", v)):
        if rec is not None and experiment.random_input and rec.get("input_t") is None:
            raise ValueError(f"{name}: the experiment's input is random-binary, so the {name} record needs its input "
                             "realisation (input_t and input_u, as simulate and read_record return them)")
    # The study layer's selection reads its records from files, as the command line gives them.
    with tempfile.TemporaryDirectory(prefix="jitterid-select-") as tmp:
        paths = {name: os.path.join(tmp, f"{name}.csv") for name in ("record", "validation")}
        _write_record(paths["record"], r, "record")
        if v is not None:
            _write_record(paths["validation"], v, "validation")
        try:
            text = _jitterid.select(experiment, paths["record"], None if v is None else paths["validation"], limit)
        except ValueError as e:
            # The files are this call's own: name the arguments they hold, not the files.
            message = str(e)
            for name, path in paths.items():
                message = message.replace(path[: -len(".csv")] + ".input.csv", f"{name}['input_t', 'input_u']")
                message = message.replace(path, name)
            raise ValueError(message) from None
    return SelectionResult(json.loads(text))


def design(experiment: Experiment, criterion: Optional[str] = None, *, budget: Optional[str] = None,
           jitter_blind: bool = False, write_input: Optional[Union[str, os.PathLike]] = None,
           derived: Optional[Iterable[str]] = None, dac_rate: Optional[float] = None) -> DesignResult:
    """The experiment that makes ``experiment``'s estimate most precise, over the free
    variables of its ``[design]`` section (see ``docs/experiments.md``), as ``jitterid design
    --json [--criterion] [--budget] [--jitter-blind] [--write-input] [--derived]``.

    * ``criterion``: ``"d"`` (log det of the predicted covariance), ``"a"`` (its trace) or
      ``"param:NAME"`` (one parameter's variance); the section's by default.
    * ``budget``: ``"duration=SECONDS"`` or ``"samples=N"``, the record every design has,
      replacing the section's.
    * ``jitter_blind``: also the design that ignores the jitter, predicted under the true prior.
    * ``write_input``: a path ``FILE.csv``: writes the designed input there and the experiment
      that reads it to ``FILE.toml``, ready for ``Experiment.from_toml`` and ``simulate``; for a
      designed multisine (``[design] band``), the experiment with its tones to ``FILE.toml`` and
      its sample sequence at ``dac_rate`` Hz (``[design] dac_rate`` by default) to ``FILE.csv``.
    * ``dac_rate``: the DAC rate of a designed multisine's sample sequence, as ``--dac-rate``.
    * ``derived``: the derived quantities whose predicted standard deviations are reported
      (``result.derived``), replacing ``[design] derived``: ``"static_gain"``,
      ``"pole_frequency"`` (every pole's ``|p|/2π``, named ``pole1.frequency``, … in increasing
      order), ``"poleK.frequency"``, ``"gain@F"`` (``|G|`` at ``F`` Hz), ``"jitter.sigma"``.

    With ``[design] low`` or ``high`` (the random binary input's levels free), ``result.design``
    and ``result.baseline`` carry both levels, ``"low"`` and ``"high"``, and the written input
    takes the designed ones.

    The search runs without the GIL. A ``[design]`` without a feasible point, a budget that
    cannot be met, an unknown criterion or an unknown or undefined derived quantity raise
    ``ValueError`` naming the key."""
    _experiment(experiment)
    for name, value in (("criterion", criterion), ("budget", budget)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{name}: expected text such as 'd' or 'samples=400', found {type(value).__name__}")
    names = None
    if derived is not None:
        if isinstance(derived, str):
            raise TypeError("derived: expected a list of names such as ['static_gain', 'pole_frequency'], found a str")
        names = list(derived)
        if not all(isinstance(n, str) for n in names):
            raise TypeError("derived: expected a list of names such as ['static_gain', 'pole_frequency']")
    if dac_rate is not None and (isinstance(dac_rate, bool) or not isinstance(dac_rate, (int, float))):
        raise TypeError(f"dac_rate: expected a number of Hz, found {type(dac_rate).__name__}")
    target = None if write_input is None else os.fspath(write_input)
    if target is not None and not target.endswith(".csv"):
        raise ValueError(f"write_input: expected a path ending in .csv (the experiment goes beside it as .toml), "
                         f"found {target!r}")
    text, written = _jitterid.design(experiment, criterion, bool(jitter_blind), budget,
                                     None if target is None else os.path.basename(target), names,
                                     None if dac_rate is None else float(dac_rate))
    if target is not None and written is not None:
        csv, toml = written
        with open(target, "w") as out:
            out.write(csv)
        with open(target[: -len(".csv")] + ".toml", "w") as out:
            out.write(toml)
    return DesignResult(json.loads(text))


def montecarlo(
    experiment: Experiment,
    runs: int = 128,
    seed: int = DEFAULT_SEED,
    shard: Optional[Tuple[int, int]] = None,
    method: Optional[str] = None,
    threads: Optional[int] = None,
    *,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> MonteCarloResult:
    """``runs`` realisations of ``experiment`` fitted with ``method`` under master ``seed``
    (or shard ``(i, n)`` of them), on ``threads`` worker threads (all cores by default).
    ``to_dict()`` equals ``jitterid montecarlo --json`` (``--shard i/n``) apart from
    ``seconds``.

    The GIL is released while it runs. ``progress``, if given, is called as
    ``progress(done, total)`` as realisations finish, on the calling thread. Ctrl-C, or an
    exception raised by ``progress``, stops the study before its next realisations and is
    raised once the running ones end (a study has no partial result); a
    ``KeyboardInterrupt``'s ``__cause__`` says how many realisations ran."""
    _experiment(experiment)
    if integer(runs, "runs") < 1:
        raise ValueError(f"runs: expected at least 1 realisation, found {runs}")
    text = _jitterid.montecarlo(experiment, runs, integer(seed, "seed"), shard, _method(method), threads, progress)
    return MonteCarloResult(json.loads(text))


def merge(shards: Iterable[Union[MonteCarloResult, Mapping[str, Any]]]) -> MonteCarloResult:
    """The result of the unsharded study from all its shards (results of ``montecarlo`` with
    ``shard=(i, n)``, or their ``to_dict()``, or the command line's shard files read as JSON),
    checked to belong together and to be whole, as ``jitterid merge --json``."""
    texts = [json.dumps(s.to_dict() if isinstance(s, MonteCarloResult) else dict(s)) for s in shards]
    return MonteCarloResult(json.loads(_jitterid.merge(texts)))


def read_record(path: Union[str, os.PathLike], input: Optional[Union[str, os.PathLike]] = None) -> dict:
    """The columns of a data file written by ``jitterid simulate`` (``k``, ``t``, ``y``, …) as
    arrays, with the input realisation ``input_t``, ``input_u`` from its side file
    ``<name>.input.csv`` (or ``input``) when there is one."""
    return _jitterid.read_record(os.fspath(path), None if input is None else os.fspath(input))


def _grid(samples: int, interval: float, start: float) -> tuple:
    return integer(samples, "samples"), real_number(interval, "interval"), real_number(start, "start")


def _model(system: Any, jitter_model: Any, input: Any) -> None:
    """Refuses a system, jitter model or input of the wrong type, naming the argument."""
    if not isinstance(system, _jitterid.System):
        raise TypeError(f"system: expected a System, found {type(system).__name__}")
    if not isinstance(jitter_model, _jitterid.Jitter):
        raise TypeError(f"jitter: expected a jitter model (jitterid.jitter), found {type(jitter_model).__name__}")
    if input is not None and not isinstance(input, _jitterid.Input):
        raise TypeError(f"input: expected an Input or None, found {type(input).__name__}")


Inputs = Union[Iterable[Input], Mapping[str, Input]]


def _driven(system: Any, input: Any, inputs: Optional[Inputs]) -> Tuple[Any, list]:
    """The system and the inputs that drive it, in its input order: ``(system, [(name,
    input)])``, the name ``None`` for a system with one input.

    ``inputs`` is a list (in the system's input order) or a dict by input name. Refuses
    ``input`` and ``inputs`` together, a count or a name that does not match the system's
    inputs."""
    if inputs is None:
        if getattr(system, "inputs", None) is not None:
            raise ValueError(f"inputs: the system has several inputs ({', '.join(system.inputs)}); give one Input per "
                             "input as inputs=[...] or a dict by input name")
        return system, [] if input is None else [(None, input)]
    if input is not None:
        raise ValueError("input, inputs: give the one input as input=, or several as inputs=[...], not both")
    names = getattr(system, "inputs", None)
    if isinstance(inputs, Mapping):
        given = {str(k): v for k, v in inputs.items()}
        if names is None or sorted(given) != sorted(names):
            expected = "one input (input=)" if names is None else f"the inputs {names}"
            raise ValueError(f"inputs: the system has {expected}, found inputs named {sorted(given)}")
        pairs = [(n, given[n]) for n in names]
    else:
        try:
            listed = list(inputs)
        except TypeError:
            raise TypeError(f"inputs: expected a list of Inputs or a dict of them by input name, found "
                            f"{type(inputs).__name__}") from None
        if names is None:
            if len(listed) != 1:
                raise ValueError(f"inputs: the system has one input, found {len(listed)} inputs; a system with several "
                                 "inputs is System.several([...]) or a grey-box model whose b has a column per input")
        elif len(listed) != len(names):
            raise ValueError(f"inputs: the system has {len(names)} inputs ({', '.join(names)}), found {len(listed)}")
        pairs = list(zip([None] if names is None else names, listed))
    for i, (name, u) in enumerate(pairs):
        if not isinstance(u, (_jitterid.Input, _Realisation)):
            raise TypeError(f"inputs[{i if name is None else repr(name)}]: expected an Input, found {type(u).__name__}")
    return system, pairs


def _system_sections(spec: Mapping[str, Any], inputs: list, estimate: bool) -> Tuple[Any, Any]:
    """The ``[system]`` and ``[input]`` sections of an experiment for the system ``spec``
    (without its output offset) driven by ``inputs`` (as ``_driven`` gives them): one table
    each for one input; for several, an ``[[input]]`` table per input with its ``name``, and a
    ``[[system]]`` table per input or, for a shared grey-box model, one ``[system]`` whose
    ``b`` and ``d`` have a column per input."""
    def section(u: Any) -> dict:
        return dict(u) if isinstance(u, _Realisation) else json.loads(u.section_json())

    def level_keys(table: Mapping[str, Any]) -> Tuple[dict, dict]:
        # The input's level is a key of the system's spec and of the input's section.
        table = dict(table)
        return table, {k: table.pop(k) for k in _LEVEL_KEYS if k in table}

    if not inputs or inputs[0][0] is None:
        spec, level = level_keys(spec)
        return dict(spec, estimate=estimate), None if not inputs else dict(section(inputs[0][1]), **level)
    input_tables = [dict(section(u), name=name) for name, u in inputs]
    channels = []
    for table, c in zip(input_tables, spec["channels"]):
        c, level = level_keys(c)
        table.update(level)
        channels.append(c)
    if not spec.get("shared"):
        return [dict(c, estimate=estimate) for c in channels], input_tables
    one = dict(channels[0], estimate=estimate)
    one["b"] = [[c["b"][i][0] for c in channels] for i in range(len(one["b"]))]
    if "d" in one:
        one["d"] = [[c["d"][0][0] for c in channels]]
    return one, input_tables


_LEVEL_KEYS = ("level", "estimate_level")


def _level(system: Any, level: Any, estimate_level: Any) -> Any:
    """``system`` with the input's level ``u₀`` (``[input] level``) and whether it is estimated
    (``estimate_level``) in its spec when given (the system's own otherwise: a fitted system
    carries them). Only a system with one input takes them here; ``level`` not a real number
    and ``estimate_level`` not a boolean raise ``ValueError`` naming the argument."""
    if level is None and estimate_level is None:
        return system
    if getattr(system, "inputs", None) is not None:
        raise ValueError("level: a system with several inputs takes each input's level in an experiment file "
                         "([[input]] level, estimate_level)")
    spec = dict(system.spec)
    if level is not None:
        if isinstance(level, (bool, np.bool_)):
            raise ValueError("level: expected a real number, found bool")
        try:
            spec["level"] = real_number(level, "level")
        except TypeError as e:
            raise ValueError(str(e)) from None
        if not np.isfinite(spec["level"]):
            raise ValueError(f"level: expected a finite number, found {spec['level']}")
    if estimate_level is not None:
        if not isinstance(estimate_level, (bool, np.bool_)):
            raise ValueError(f"estimate_level: expected True or False, found {type(estimate_level).__name__}")
        spec["estimate_level"] = bool(estimate_level)
    return System(json.dumps(spec))


def _output(system: Any, offset: Any, estimate_offset: Any) -> Tuple[Any, dict, Optional[dict]]:
    """The output offset of a set-up: ``(system, system_keys, output)``.

    A ``System`` may carry the registry keys ``offset`` and ``estimate_offset`` itself (a fitted
    system does); the arguments ``offset`` and ``estimate_offset``, when given, replace them.
    ``system`` is the system with the offset in its spec (what the extension simulates),
    ``system_keys`` its ``[system]`` section without the two keys, and ``output`` the
    ``[output]`` section (``None`` without either key, so that nothing changes). ``offset`` not
    a real number and ``estimate_offset`` not a boolean raise ``ValueError`` naming the
    argument; its range is the experiment reader's to check."""
    spec = dict(system.spec)
    output = {k: spec.pop(k) for k in ("offset", "estimate_offset") if k in spec}
    if offset is not None:
        if isinstance(offset, (bool, np.bool_)):
            raise ValueError("offset: expected a real number, found bool")
        try:
            output["offset"] = real_number(offset, "offset")
        except TypeError as e:
            raise ValueError(str(e)) from None
        if not np.isfinite(output["offset"]):
            raise ValueError(f"offset: expected a finite number, found {output['offset']}")
    if estimate_offset is not None:
        if not isinstance(estimate_offset, (bool, np.bool_)):
            raise ValueError(f"estimate_offset: expected True or False, found {type(estimate_offset).__name__}")
        output["estimate_offset"] = bool(estimate_offset)
    if not output:
        return system, spec, None
    if offset is not None or estimate_offset is not None:
        system = System(json.dumps(dict(spec, **output)))
    return system, spec, output


def _in_range(system: Any, jitter_model: Any, inputs: list, samples: Any, interval: Any, start: Any,
              noise_std: Any, what: str, output: Optional[dict] = None) -> None:
    """Refuses what the command line refuses for the same set-up: the arguments are read as
    the sections of an experiment file (``[sampling]``, ``[input]``, ``[system]``, ``[jitter]``,
    ``[noise]``), whose reader checks every value against the grid (a zero gain, a pole or a
    jitter width outside the representable range, a sample count beyond the limit) and names
    the argument's key in its ``ValueError``."""
    from ._spec import spec_json

    samples, interval, start = _grid(samples, interval, start)
    sections: dict = {"sampling": {"interval": interval, "samples": samples, "start": start}}
    spec = dict(system.spec)
    for key in ("offset", "estimate_offset"):
        spec.pop(key, None)
    sections["system"], input_section = _system_sections(spec, inputs, False)
    if input_section is not None:
        sections["input"] = input_section
    if output is not None:
        # Only the offset's value is checked here: nothing is estimated.
        sections["output"] = {k: v for k, v in output.items() if k == "offset"}
    sections["jitter"] = dict(jitter_model.spec, estimate=False)
    sections["noise"] = {"std": real_number(noise_std, "noise_std"), "estimate": False}
    Experiment.from_sections(spec_json(sections), what)


def _checked(system: Any, jitter_model: Any, input: Any, inputs: Optional[Inputs]) -> Tuple[Any, list]:
    """The arguments' types checked and the system with its inputs (``_driven``)."""
    if isinstance(system, (list, tuple, Mapping)):
        system = System.several(system)
    _model(system, jitter_model, input)
    return _driven(system, input, inputs)


class _Realisation(dict):
    """An input realisation a record holds, as its ``[input]`` section (a ``piecewise`` input)."""


def _piecewise(t: Any, u: Any, name: str) -> _Realisation:
    """The input realisation a record holds (switch times ``input_t``, levels ``u``, with or
    without the side file's closing 0) as a ``piecewise`` ``[input]`` section."""
    levels = real_array(u, name)
    times = real_array(t, "input_t")
    closed = levels.ndim == 1 and len(levels) >= 2 and levels[-1] == 0.0
    return _Realisation(kind="piecewise", times=times.tolist(), values=(levels[:-1] if closed else levels).tolist())


def _record_inputs(system: Any, record: Mapping[str, Any]) -> Optional[Dict[str, _Realisation]]:
    """A record's input realisations by input name, for a system with several inputs (``None``
    otherwise, and for a record without them): ``input_t`` the switch times, ``input_u`` a
    dict of levels by input name, as ``Experiment.simulate`` gives them."""
    several = isinstance(system, (list, tuple, Mapping)) or getattr(system, "inputs", None) is not None
    levels = record.get("input_u")
    if not several or record.get("input_t") is None or not isinstance(levels, Mapping):
        return None
    return {str(name): _piecewise(record["input_t"], u, f"input_u[{name!r}]") for name, u in levels.items()}


def simulate(system: Union[System, Iterable[System], Mapping[str, System]], jitter: jitter.Jitter,
             input: Optional[Input] = None, *, samples: int, interval: float, start: float = 0.0,
             noise_std: float = 0.0, seed: int = DEFAULT_SEED, truth: bool = False,
             offset: Optional[float] = None, inputs: Optional[Inputs] = None,
             level: Optional[float] = None) -> dict:
    """``samples`` jittered samples ``y_k = y₀ + s(t_k + τ_k) + v_k`` of ``system`` driven by
    ``input`` at ``t_k = start + k·interval``, white noise of std ``noise_std``, seeded by
    ``seed``: a dict of arrays ``t``, ``y``, ``u`` (with an input), and with ``truth`` the drawn
    ``tau`` and ``v``. ``offset`` is the output offset ``y₀`` (the operating point, as
    ``[output] offset``; default the system's own, else 0). ``level`` is the input's level
    ``u₀`` (as ``[input] level``: the system is driven by ``u − u₀`` over the input's span; one
    input). The GIL is released while it runs.
    The arguments are checked as the command line checks an experiment file (``ValueError``
    naming the key).

    Several inputs: ``system`` a system with several inputs (``System.several``, a grey-box
    model with a column of ``b`` per input) or a list or dict of systems, one per input, and
    ``inputs`` a list of Inputs in the system's input order or a dict by input name; ``u`` is
    then a dict of arrays by input name."""
    system, pairs = _checked(system, jitter, input, inputs)
    system = _level(system, level, None)
    system, _, output = _output(system, offset, None)
    _in_range(system, jitter, pairs, samples, interval, start, noise_std, "simulate arguments", output)
    return _jitterid.simulate(system, jitter, [u for _, u in pairs], *_grid(samples, interval, start),
                              real_number(noise_std, "noise_std"), integer(seed, "seed"), bool(truth))


def first_moment(system: Union[System, Iterable[System], Mapping[str, System]], jitter: jitter.Jitter,
                 input: Optional[Input] = None, *, samples: int, interval: float, start: float = 0.0,
                 inputs: Optional[Inputs] = None) -> np.ndarray:
    """``m_k = E[s(t_k + τ)]`` at ``t_k = start + k·interval``, exact (``inputs`` as
    ``simulate`` takes them)."""
    system, pairs = _checked(system, jitter, input, inputs)
    _in_range(system, jitter, pairs, samples, interval, start, 0.0, "first_moment arguments")
    return _jitterid.first_moment(system, jitter, [u for _, u in pairs], *_grid(samples, interval, start))


def second_moment(system: Union[System, Iterable[System], Mapping[str, System]], jitter: jitter.Jitter,
                  input: Optional[Input] = None, *, samples: int, interval: float, start: float = 0.0,
                  noise_std: float = 0.0, inputs: Optional[Inputs] = None) -> np.ndarray:
    """``λ_k = Var y_k = noise_std² + E[s(t_k + τ)²] − m_k²`` at ``t_k = start + k·interval``,
    exact (``inputs`` as ``simulate`` takes them; with several inputs ``E[s²]`` holds the
    inputs' cross terms)."""
    system, pairs = _checked(system, jitter, input, inputs)
    _in_range(system, jitter, pairs, samples, interval, start, noise_std, "second_moment arguments")
    return _jitterid.second_moment(system, jitter, [u for _, u in pairs], *_grid(samples, interval, start),
                                   real_number(noise_std, "noise_std"))


def fit(record: Mapping[str, Any], system: System, jitter: jitter.Jitter, method: str = "bcls", *,
        estimate: Iterable[str] = ("system",), interval: Optional[float] = None,
        start: Optional[float] = None, input: Optional[Input] = None, noise_std: float = 0.0,
        options: Optional[Mapping[str, Any]] = None, init: str = "experiment",
        progress: Optional[Callable[[int, float], Any]] = None, offset: Optional[float] = None,
        estimate_offset: Optional[bool] = None, inputs: Optional[Inputs] = None,
        level: Optional[float] = None, estimate_level: Optional[bool] = None) -> FitResult:
    """Fits a record's samples with ``method``, starting from ``system`` and ``jitter``.

    Arguments:

    * ``record``: a mapping with the samples ``y`` (real, finite) and optionally ``T`` and
      ``t0`` or the sample times ``t``, and the input (``input``, or ``input_t`` and ``input_u``
      as ``simulate`` gives them); or a pandas DataFrame (columns ``y`` and ``t``, or the
      times as its index) or Series (the samples, the times as its index), or an xarray
      Dataset or DataArray (the times as its coordinate). A ``t`` must have one finite time per sample, on the grid
      ``start + k·interval`` (within the command line's tolerance for a data file's ``t``
      column, ``1e-6·interval``); it gives the grid when ``interval``/``start`` and ``T``/``t0``
      do not.
    * ``system``, ``jitter``: the model, and the start of the estimated parts.
    * ``method``: ``"ls"``, ``"bcls"``, ``"bj"``, ``"ml"``, … (the command line's methods).
    * ``estimate``: the estimated parts among ``"system"``, ``"jitter"`` and ``"noise"`` (one
      part alone may be given as its name).
    * ``interval``, ``start``: the grid (default: the record's ``T``/``t0``, else its ``t``).
    * ``input``: the known input (default: the record's).
    * ``inputs``: for a system with several inputs (``System.several``, a grey-box model with a
      column of ``b`` per input, or ``system`` given as a list or dict of systems), the known
      inputs as a list in the system's input order or a dict by input name (default: the
      record's ``input_t`` and ``input_u``, ``input_u`` a dict of levels by input name as
      ``Experiment.simulate`` gives it). Parameters are named by input (``torque.b0``).
    * ``noise_std``: the measurement-noise level (known, or the start when estimated).
    * ``options``: further keys of the experiment file's ``[estimate]`` section
      (``solver``, ``frequencies``, ``max_iterations``, …).
    * ``init``: where the search starts: ``"experiment"`` (``system`` as given), ``"auto"``
      (the data-driven initializer's model, as ``jitterid fit --init auto``) or
      ``"experiment-only"``.
    * ``progress``: called as ``progress(iteration, cost)`` after the solver's start and each
      of its iterations, on the calling thread (see ``Experiment.fit`` for Ctrl-C and for an
      exception it raises).
    * ``offset``, ``estimate_offset``: the output offset ``y₀`` (operating point) and whether
      it is estimated with the system, as the parameter ``offset`` (the keys of ``[output]``;
      default the system's own, else no offset). ``estimate_offset=True`` needs ``"system"``
      among the estimated parts.
    * ``level``, ``estimate_level``: the input's level ``u₀`` (the system is driven by
      ``u − u₀``) and whether it is estimated with the system, as the parameter ``level`` (the
      keys of ``[input]``; default the system's own, else none; one input). Estimated, it
      needs ``"system"`` among the estimated parts and, through a system that settles to a
      static gain, a known offset (both would be constants in the output).

    Returns a ``FitResult`` (``names``, ``params``, ``std_errors``, ``covariance``, …), equal
    to ``Experiment.fit`` on an experiment with the same sections. Raises ``ValueError``
    naming the argument or key at fault (NaN or infinite samples or times, a ``t`` off the
    grid or of the wrong length), ``TypeError`` for a record that is not a mapping and for
    arguments of the wrong type (complex or non-numeric samples, a system that is not a
    ``System``).
    Each call reads the experiment its arguments spell: for many fits of one set-up, make an
    ``Experiment`` once and call its ``fit``.

    Example::

        record = jitterid.simulate(G, J, u, samples=200, interval=1.0, noise_std=0.01)
        fit = jitterid.fit(dict(record, input=u), G, J, "bcls", noise_std=0.01)
        fit.params, fit.std_errors
    """
    record = as_record(record)
    if input is None and inputs is None:
        inputs = record.get("input") if isinstance(record.get("input"), (list, tuple, Mapping)) else \
            _record_inputs(system, record)
    system, pairs = _checked(system, jitter, input, inputs)
    _method(method)
    if isinstance(estimate, str):
        # One part named alone, as `estimate="jitter"`, is that part.
        estimate = (estimate,)
    try:
        parts = set(estimate)
    except TypeError:
        raise TypeError(f"estimate: expected the estimated parts, such as ('system', 'jitter'), found "
                        f"{type(estimate).__name__}") from None
    unknown = parts - {"system", "jitter", "noise"}
    if unknown:
        raise ValueError(f"estimate: unknown part(s) {sorted(map(str, unknown))}; expected 'system', 'jitter' or "
                         "'noise'")
    y = real_array(record["y"], "y")
    if y.ndim != 1:
        raise ValueError(f"y: expected a one-dimensional array, found shape {y.shape}")
    t = record.get("t")
    if t is not None:
        # Checked here because the grid is taken from it; the extension checks it against that grid.
        t = real_array(t, "t")
        if t.ndim != 1 or t.size != y.size:
            raise ValueError(f"t: has shape {t.shape}, expected ({y.size},) (one time per sample of y)")
        bad = np.flatnonzero(~np.isfinite(t))
        if bad.size:
            raise ValueError(f"t: element {bad[0]} is {t[bad[0]]} (not a finite number)")
    if interval is None:
        interval = record.get("T")
        if interval is None and t is not None and t.size > 1:
            interval = (t[-1] - t[0]) / (t.size - 1)
        if interval is None:
            raise ValueError("interval: not given and the record has no `T` or `t` to take it from")
    if start is None:
        start = record.get("t0", t[0] if t is not None and t.size else 0.0)
    sections: dict = {"sampling": {"interval": real_number(interval, "interval"), "samples": int(y.size),
                                   "start": real_number(start, "start")}}
    if not pairs:
        input = record.get("input")
        if input is not None and not isinstance(input, _jitterid.Input):
            raise TypeError(f"record['input']: expected an Input, found {type(input).__name__}")
        if input is None and record.get("input_t") is not None:
            input = _piecewise(record["input_t"], record.get("input_u"), "input_u")
        pairs = [] if input is None else [(None, input)]
    if options is not None and not isinstance(options, Mapping):
        raise TypeError(f"options: expected a mapping of [estimate] keys, found {type(options).__name__}")
    system = _level(system, level, estimate_level)
    _, system_keys, output = _output(system, offset, estimate_offset)
    sections["system"], input_section = _system_sections(system_keys, pairs, "system" in parts)
    if input_section is not None:
        sections["input"] = input_section
    if output is not None:
        sections["output"] = output
    sections["jitter"] = dict(jitter.spec, estimate="jitter" in parts)
    sections["noise"] = {"std": real_number(noise_std, "noise_std"), "estimate": "noise" in parts}
    sections["estimate"] = {"method": method, **dict(options or {})}
    from ._spec import spec_json

    exp = Experiment.from_sections(spec_json(sections), "fit arguments")
    return exp.fit({"y": y} if t is None else {"y": y, "t": t}, init=init, progress=progress)
