"""A seeded random driver over the public API of the ``jitterid`` package: every function of the
modules' ``__all__``, every class's constructor, public methods and properties, called with
arguments drawn from a pool of hostile values (and from plausible ones, so that calls reach
past the first argument's check), each call in a fresh interpreter under a memory limit and a
time limit.

A call may return, or raise ``ValueError``, ``TypeError``, ``OverflowError``, ``MemoryError``,
``KeyError``, ``OSError``, ``ImportError`` (a conversion whose optional package, SciPy or
python-control, is not installed: the message says what to install) or the exception of a
hostile callback handed to it; anything else
is a finding: a Rust panic (``PanicException``), the interpreter's death by a signal (an abort
on a failed allocation, a segmentation fault), a call that does not return within the time
limit, or an exception of another type (``AttributeError``, ``IndexError``, ``RuntimeError``…:
an argument that no check stopped).

For speed, calls run in batches, one interpreter per batch; a call that kills or hangs its
batch's interpreter, or that ends in a finding, is run again alone in its own interpreter, and
that solo run is what is reported, so every finding comes with a one-call reproducer.

    python python/tests/fuzz_driver.py --calls 5000 --seed 1     # a long run
    python python/tests/fuzz_driver.py --replay "R['J'].sample(2**62, 1)"

A reproducer runs after ``PRELUDE``: ``R['EXP']``, ``R['G']``, ``R['J']``… are the receivers
its ``RECIPES`` make (the Table 2 experiment, a second-order system, a uniform-sum jitter…).

``python/tests/test_fuzz.py`` runs a small seeded version in CI (``JITTERID_FUZZ_CALLS`` sets
its size).
"""

from __future__ import annotations

import argparse
import inspect
import json
import keyword
import os
import queue
import random
import signal
import subprocess
import sys
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence

REPO = Path(__file__).resolve().parents[2]
TABLE2 = REPO / "examples" / "experiments" / "table2.toml"

#: The interpreter's address-space limit: far above what any sane call needs, far below what
#: the machine has, so that an allocation sized by a hostile argument fails instead of
#: swapping the machine to a halt.
MEMORY_LIMIT = 4 << 30
#: Seconds a single call may take (checked from the parent, since a call that hangs without
#: releasing the GIL cannot be interrupted from inside its interpreter).
CALL_TIMEOUT = 60.0
#: Calls per interpreter.
BATCH = 10

#: Exception types that are a clean refusal. ``Hostile`` is raised by the hostile callables of
#: the pool (a progress callback that raises must have its exception propagate); ``ImportError``
#: is an optional package's absence, named in the message.
FINE = (
    "ValueError",
    "TypeError",
    "OverflowError",
    "MemoryError",
    "KeyError",
    "OSError",
    "ImportError",
    "Hostile",
)

#: What every interpreter runs before its calls: the receivers (objects whose methods are
#: called), made on first use, and the names the pools' expressions use.
PRELUDE = f"""
import json, math, sys
import numpy as np
import jitterid
from jitterid import jitter, system, inputs

class Hostile(Exception):
    '''Raised by the pool's hostile callables.'''

def raising(*args, **kwargs):
    raise Hostile("a hostile callback")

class Lazy(dict):
    def __missing__(self, key):
        value = self[key] = RECIPES[key]()
        return value

RECIPES = {{
    "EXP": lambda: jitterid.Experiment.from_toml({str(TABLE2)!r}),
    "REC": lambda: R["EXP"].simulate(seed=1),
    "FIT": lambda: R["EXP"].fit(R["REC"]),
    "VAL": lambda: jitterid.validate(R["EXP"], R["REC"]),
    "SEL": lambda: jitterid.SelectionResult({{"best": None, "candidates": []}}),
    "DES": lambda: jitterid.DesignResult({{"criterion": "d", "design": {{"interval": 1.0, "samples": 10}},
                                          "predicted": [{{"name": "gain", "std": 0.1}}]}}),
    "MC": lambda: jitterid.montecarlo(R["EXP"], runs=2, seed=1, threads=1),
    "MC0": lambda: jitterid.montecarlo(R["EXP"], runs=4, seed=1, shard=(0, 2), threads=1),
    "MC1": lambda: jitterid.montecarlo(R["EXP"], runs=4, seed=1, shard=(1, 2), threads=1),
    "G": lambda: jitterid.System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2),
    "GD": lambda: system.from_name("zpk", gain=0.2, zeros=[-0.5], poles=[[-0.25, 0.3]], delay=1.3),
    "H": lambda: jitterid.System.tf([0.2, 0.1], [1.0, 0.5, 0.1525]),
    "GS": lambda: jitterid.System.several({{"torque": R["G"], "brake": R["H"]}}),
    "J": lambda: jitter.UniformSum(n=2, a=0.28867513459481287),
    "JG": lambda: jitter.Gaussian(sigma=0.1),
    "JS": lambda: jitter.from_name("sum", terms=[dict(family="gaussian", sigma=0.1),
                                                 dict(family="uniform-sum", a=0.2)]),
    "JM": lambda: jitter.from_name("mixture", terms=[dict(family="gaussian", sigma=0.1),
                                                     dict(family="laplace", scale=0.2)], weights=[0.3, 0.7]),
    "U": lambda: inputs.random_binary(0.0, 31.0, seed=5),
    "UZ": lambda: inputs.zero_order_hold([0.0, 1.0, 1.0, 0.0], interval=5.0),
    "UT": lambda: inputs.multisine([0.05, 0.1], [1.0, 0.5]),
}}
R = Lazy()
"""

#: Receivers by class name; the family classes of ``jitterid.jitter`` take the family's own
#: member (``jitter.from_std``) or, failing that, any jitter model.
RECEIVERS: Dict[str, List[str]] = {
    "Experiment": ["EXP"],
    "FitResult": ["FIT"],
    "MonteCarloResult": ["MC", "MC0"],
    "ValidationResult": ["VAL"],
    "SelectionResult": ["SEL"],
    "DesignResult": ["DES"],
    "System": ["G", "GD", "H", "GS"],
    "Jitter": ["J", "JG", "JS", "JM"],
    "Sum": ["JS"],
    "Mixture": ["JM"],
    "Input": ["U", "UZ", "UT"],
}

#: Hostile values, as Python expressions.
HOSTILE: Sequence[str] = (
    "None", "float('nan')", "float('inf')", "-float('inf')", "1e308", "-1e300", "1e-300", "0", "-1", "0.0",
    "-0.5", "True", "2**62", "10**12", "2**64", "-2**63", "10**400", "''", "'abc'", "'gaussian'", "'../x'",
    "b'x'", "[]", "[[]]", "[1.0, [2.0]]", "[[1.0], [1.0, 2.0]]", "[1+2j]", "1j", "1+2j", "np.array([1+2j])",
    "np.zeros(0)", "np.zeros((2, 0))", "np.full(3, np.nan)", "np.array([np.inf, 1.0])", "np.array([1e308, -1e308])",
    "np.arange(6.0).reshape(2, 3)", "np.array(['a'])", "np.array([None])", "[None]", "[float('nan')]", "{}",
    "{'a': 1}", "{'y': [1.0]}", "{'y': [float('nan')]}", "[[1.0, 2.0], [3.0, 4.0]]", "object()", "(1, 2, 3)",
    "set()", "raising", "np.float32(3e38)", "np.int64(-1)", "np.uint64(2**64 - 1)", "[2**62]", "[10**12, 1.0]",
    "{'family': 'sum', 'terms': []}", "'{}'", "'[]'", "'{\"family\": \"gaussian\", \"sigma\": 1e308}'",
)

#: Hostile values for an argument that takes a count or an integer (drawn half the time for
#: such arguments: sizes are where allocations come from).
HOSTILE_INTEGERS: Sequence[str] = ("0", "-1", "2**31", "2**62", "10**12", "2**64", "-2**63", "10**400", "True",
                                   "2.5", "np.uint64(2**64 - 1)")

#: Hostile values for an argument that takes a real number.
HOSTILE_REALS: Sequence[str] = ("float('nan')", "float('inf')", "-float('inf')", "1e308", "-1e300", "1e-300",
                                "5e-324", "0.0", "-0.5", "-1e-12", "10**400")

#: Values too large for the small version (each may take the whole time limit until the
#: library bounds them): many poles, tones, times. Added by ``--large``.
LARGE: Sequence[str] = ("np.full(1000, -1.0)", "np.linspace(0.01, 0.49, 10_000)", "np.arange(10**6) * 1.0",
                        "[{'family': 'uniform-sum', 'a': 0.1}] * 40")

#: Arguments that take arrays, which the ``LARGE`` values are aimed at.
ARRAYS = frozenset(("poles", "zeros", "num", "den", "frequencies", "amplitudes", "phases", "edges", "levels",
                    "values", "terms", "f", "t", "z", "y"))

#: Plausible values by argument name, as Python expressions.
PLAUSIBLE: Dict[str, Sequence[str]] = {
    "weights": ("[0.5, 0.5]",), "fixed_weights": ("True",), "d": ("0.1",), "mean": ("0.1",),
    "samples": ("20", "3"), "interval": ("1.0", "0.5"), "start": ("0.0", "2.0"), "end": ("30.0",),
    "noise_std": ("0.01", "0.0"), "seed": ("1", "7"), "run": ("0", "2"), "truth": ("True", "False"),
    "system": ("R['G']", "R['GD']"), "jitter": ("R['J']", "R['JG']"), "input": ("R['U']", "None", "R['UT']"),
    "record": ("R['REC']", "dict(R['REC'])", "{'y': R['REC']['y'], 'T': 1.0}"),
    "method": ("'bcls'", "'ls'", "None"), "experiment": ("R['EXP']",), "runs": ("2", "3"),
    "shard": ("(0, 2)", "None"), "threads": ("1", "None"), "f": ("[0.0, 0.1]", "0.3"), "t": ("[0.0, 1.5]", "2.0"),
    "z": ("[0.1j, -0.2]",), "size": ("5", "0"), "edges": ("[0.0, 1.0, 3.0]",), "levels": ("[1.0, 0.0]",),
    "values": ("[0.0, 1.0, 1.0]",), "frequencies": ("[0.05, 0.1]",), "amplitudes": ("[1.0, 0.5]", "None"),
    "phases": ("None", "[0.0, 0.1]"), "zeros": ("[-0.5]", "[]"), "poles": ("[-0.25+0.3j, -0.25-0.3j]", "[-1.0]"),
    "gain": ("0.2",), "num": ("[0.2, 0.1]",), "den": ("[1.0, 0.5, 0.1525]",),
    "family": ("'gaussian'", "'uniform-sum'", "'sum'"), "sigma": ("0.1",), "a": ("0.3",), "n": ("2",),
    "scale": ("0.05",), "kind": ("'zpk'", "'tf'"), "name": ("'gain'", "'gaussian'"),
    "spec": ("R['J'].spec_json", "R['G'].spec_json", "'{}'"), "json": ("R['U'].to_json()",),
    "text": ("R['EXP'].text",), "file": ("'f.toml'",), "dir": ("'.'",), "path": (repr(str(TABLE2)),),
    "shards": ("[R['MC0'], R['MC1']]",), "progress": ("None", "lambda *a: None", "raising"),
    "full": ("True", "False"), "mean_dwell": ("8.0",), "low": ("0.0",), "high": ("1.0",),
    "frequency": ("0.05",), "amplitude": ("1.0", "0.1"), "phase": ("0.0",), "estimate": ("('system',)", "['jitter']"),
    "options": ("None", "{'solver': 'lm'}", "{'max_iterations': 3}"), "y": ("R['REC']['y']",),
    "input_t": ("R['REC']['input_t']", "None"), "input_u": ("R['REC']['input_u']", "None"),
    "sections": ("json.dumps({'sampling': {'interval': 1.0, 'samples': 5}})",), "allow_paths_outside": ("False",),
    "data": ("R['MC'].to_dict()", "R['FIT'].to_dict(full=True)"), "other": ("R['G']", "R['J']"),
    "terms": ("[{'family': 'gaussian', 'sigma': 0.1}]",), "key": ("'gain'",), "delay": ("1.0",),
    "validation": ("None", "R['EXP'].simulate(seed=2)"), "fit": ("None", "R['FIT']"), "level": ("0.05", "0.01"),
    "init": ("'experiment'", "'auto'"), "time_limit": ("1.0", "None"), "pade_order": ("None", "3"),
    "validated": ("R['VAL']._validated",),
}

#: Keys tried as keyword arguments where a function takes any (``from_name(family, **keys)``).
KEYS: Sequence[str] = ("sigma", "a", "n", "scale", "terms", "gain", "zeros", "poles", "num", "den", "delay",
                       "weights", "width", "no_such_key")

#: Dunder methods called like the public ones.
DUNDERS = ("__getitem__", "__eq__", "__repr__", "__reduce__", "__getnewargs__", "__getnewargs_ex__")


@dataclass
class Target:
    """Something to call: ``expr`` is the callable (or, for a property, the attribute read)
    with ``{recv}`` standing for a receiver; ``params`` its parameters."""

    name: str
    expr: str
    params: Optional[List[inspect.Parameter]]
    receivers: List[str] = field(default_factory=list)
    keys: Sequence[str] = ()
    is_property: bool = False


@dataclass
class Outcome:
    """How one call ended: ``kind`` is ``ok``, ``fine`` (a clean refusal), ``panic``,
    ``unexpected`` (another exception type), ``signal`` (the interpreter died), ``exit`` (it
    exited without a report) or ``timeout``."""

    kind: str
    detail: str = ""
    stderr: str = ""

    @property
    def failed(self) -> bool:
        return self.kind not in ("ok", "fine")


@dataclass
class Finding:
    """A failed call, with its one-call reproducer."""

    code: str
    target: str
    outcome: Outcome

    def report(self) -> str:
        # The lines that say what happened (a panic's message, a failed allocation), not the
        # backtrace.
        said = [line for line in self.outcome.stderr.splitlines()
                if "panicked at" in line or "memory allocation" in line or "Error" in line]
        tail = said[:4] or self.outcome.stderr.strip().splitlines()[-3:]
        lines = [f"{self.target}: {self.outcome.kind}: {self.outcome.detail}", f"    reproduce: {self.code}"]
        lines += [f"    stderr: {line}" for line in tail]
        return "\n".join(lines)


def _signature(obj: object) -> Optional[List[inspect.Parameter]]:
    try:
        return list(inspect.signature(obj).parameters.values())
    except (TypeError, ValueError):
        return None


def targets() -> List[Target]:
    """Every public function, constructor, method and property of the package, enumerated from
    the modules' ``__all__`` and the classes' attributes."""
    import jitterid
    from jitterid import inputs, jitter, system

    families = {f["name"]: f for f in jitter.families()}
    found: List[Target] = []
    seen_classes = set()
    for module in (jitterid, jitter, system, inputs):
        for name in module.__all__:
            obj = getattr(module, name)
            qual = f"{module.__name__}.{name}"
            # By getattr where the name is a keyword (the family "none" has the class `None`).
            expr = qual if not keyword.iskeyword(name) else f"getattr({module.__name__}, {name!r})"
            if inspect.ismodule(obj) or not callable(obj):
                continue
            if not inspect.isclass(obj):
                keys = KEYS if any(p.kind is p.VAR_KEYWORD for p in _signature(obj) or []) else ()
                found.append(Target(qual, expr, _signature(obj), keys=keys))
                continue
            if obj in seen_classes:
                continue
            seen_classes.add(obj)
            family = getattr(obj, "family_name", None)
            members = None
            if family is not None:
                entry = families[family]
                keys = [p["key"] for p in entry["params"]] + (["terms"] if entry["takes_terms"] else [])
                found.append(Target(qual, expr, [], keys=keys))
                receivers = [f"jitter.{name}"] if _member(family) else RECEIVERS.get(name, RECEIVERS["Jitter"])
                # The family's own numbers; the rest is the base class's code, called through
                # `Jitter`'s receivers.
                members = FAMILY_MEMBERS
            else:
                found.append(Target(qual, expr, _signature(obj)))
                receivers = RECEIVERS[name]
            for attr in sorted(set(dir(obj))):
                if attr.startswith("_") and attr not in DUNDERS:
                    continue
                if members is not None and attr not in members:
                    continue
                static = inspect.getattr_static(obj, attr, None)
                if static is None or inspect.isclass(static):
                    continue
                is_property = isinstance(static, property) or type(static).__name__ == "getset_descriptor"
                member = getattr(obj, attr)
                if not is_property and not callable(member):
                    continue
                params = None if is_property else _signature(member)
                if params and params[0].name in ("self", "cls") and not isinstance(static, (staticmethod,
                                                                                            classmethod)):
                    params = params[1:]
                found.append(Target(f"{qual}.{attr}", "{recv}." + attr, params, receivers=list(receivers),
                                    is_property=is_property))
    return found


#: What a family class is called for beyond its constructor.
FAMILY_MEMBERS = ("cf", "pdf", "mgf", "sample", "std", "variance")


def _member(family: str) -> bool:
    """Whether the family has a member of standard deviation 0.1 with its default keys (the
    receiver of its class's methods)."""
    from jitterid import jitter

    try:
        jitter.from_std(family, 0.1)
        return True
    except ValueError:
        return False


def _receiver(recipe: str) -> str:
    # A family class's receiver is its member of standard deviation 0.1.
    if recipe.startswith("jitter."):
        cls = recipe.split(".", 1)[1]
        return f"jitter.from_std(getattr(jitter, {cls!r}).family_name, 0.1)"
    return f"R[{recipe!r}]"


def _kind(plausible: Sequence[str]) -> Optional[Sequence[str]]:
    """The hostile values of the argument's kind (integers or reals), judged by its plausible
    values."""
    def parses(text: str, kind: type) -> bool:
        try:
            return isinstance(eval(text, {}), kind)  # noqa: S307 (the pool's own literals)
        except Exception:
            return False

    if all(parses(v, int) and not parses(v, bool) for v in plausible):
        return HOSTILE_INTEGERS
    if all(parses(v, float) for v in plausible):
        return HOSTILE_REALS
    return None


def _value(rng: random.Random, name: str, hostile: Optional[bool], pool: Sequence[str]) -> str:
    """A value for the argument ``name``: hostile (from ``pool``, or of the argument's kind),
    plausible, or (``hostile=None``) either."""
    plausible = PLAUSIBLE.get(name)
    if hostile is None:
        hostile = not plausible or rng.random() >= 0.45
    if plausible and not hostile:
        return rng.choice(plausible)
    if name in ARRAYS and LARGE[0] in pool and rng.random() < 0.3:
        return rng.choice(LARGE)
    kind = _kind(plausible) if plausible else None
    if kind is not None and rng.random() < 0.5:
        return rng.choice(kind)
    return rng.choice(pool)


def draw_call(rng: random.Random, target: Target, pool: Sequence[str] = HOSTILE) -> str:
    """One call of ``target`` with random arguments (hostile ones from ``pool``), as a Python
    expression."""
    expr = target.expr
    if target.receivers:
        expr = expr.format(recv=_receiver(rng.choice(target.receivers)))
    if target.is_property:
        return expr
    args: List[str] = []
    kwargs: Dict[str, str] = {}
    if target.params is None:
        args = [rng.choice(pool) for _ in range(rng.randint(0, 3))]
    else:
        # Once a parameter is skipped or passed by keyword, the later ones go by keyword too,
        # so that every value reaches the parameter it was drawn for.
        by_keyword = False
        # Half the calls have one hostile argument among plausible ones, so that the hostile
        # value gets past the checks of the others to the code that uses it.
        named = [p for p in target.params if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
        single = rng.choice(named).name if named and rng.random() < 0.5 else None
        for p in target.params:
            if p.kind is p.VAR_POSITIONAL:
                if not by_keyword:
                    args += [rng.choice(pool) for _ in range(rng.randint(0, 2))]
                continue
            if p.kind is p.VAR_KEYWORD:
                continue
            if p.default is not p.empty and p.name != single and rng.random() < 0.35:
                by_keyword = True
                continue
            value = _value(rng, p.name, None if single is None else p.name == single, pool)
            if p.kind is p.POSITIONAL_ONLY or (p.kind is p.POSITIONAL_OR_KEYWORD and not by_keyword
                                                and rng.random() < 0.7):
                args.append(value)
            else:
                kwargs[p.name] = value
                by_keyword = True
        if rng.random() < 0.05:
            kwargs["no_such_argument"] = rng.choice(pool)
    for key in rng.sample(list(target.keys), k=min(len(target.keys), rng.randint(0, 3))):
        kwargs[key] = _value(rng, key, None, pool)
    text = ", ".join(args + [f"{k}={v}" for k, v in kwargs.items()])
    return f"{expr}({text})"


def draw_calls(seed: int, count: int, large: bool = False) -> List[tuple]:
    """``count`` calls ``(target name, code)`` drawn with ``seed``: targets in turn in a shuffled
    order (so that a small run still covers most of the API), arguments at random (with the
    ``LARGE`` values too if ``large``)."""
    pool = tuple(HOSTILE) + (tuple(LARGE) if large else ())
    rng = random.Random(seed)
    every = targets()
    calls = []
    while len(calls) < count:
        order = list(every)
        rng.shuffle(order)
        for t in order[: count - len(calls)]:
            calls.append((t.name, draw_call(rng, t, pool)))
    return calls


#: The child: runs the prelude, then each call of the JSON list on its standard input,
#: printing a line before and after each.
CHILD = """
import json, resource, sys
# The limits are set here rather than by a preexec_fn, which is unsafe in a parent with threads
# (the driver runs its interpreters from a thread pool).
resource.setrlimit(resource.RLIMIT_AS, ({memory}, {memory}))
# No core files: an abort must not fill the disk.
resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
calls = json.loads(sys.stdin.read())
exec(compile(PRELUDE, "<prelude>", "exec"))
FINE = {fine!r}
for i, code in calls:
    print(json.dumps({{"start": i}}), flush=True)
    try:
        eval(compile(code, "<call>", "eval"))
        out = {{"kind": "ok"}}
    except BaseException as e:
        name = type(e).__name__
        fine = any(c.__name__ in FINE for c in type(e).__mro__)
        kind = "panic" if name == "PanicException" else "fine" if fine else "unexpected"
        if isinstance(e, (SystemExit, KeyboardInterrupt)):
            kind = "unexpected"
        out = {{"kind": kind, "detail": f"{{name}}: {{str(e)[:300]}}"}}
    out["end"] = i
    print(json.dumps(out), flush=True)
"""


def run_batch(calls: Sequence[tuple], timeout: float = CALL_TIMEOUT) -> Dict[int, Outcome]:
    """Runs ``calls`` (``(index, code)``) in one interpreter; the outcome of each call that
    ran. A call that killed or hung the interpreter has its outcome; the calls after it have
    none."""
    source = f"PRELUDE = {PRELUDE!r}\n" + CHILD.format(fine=FINE, memory=MEMORY_LIMIT)
    env = dict(os.environ, RAYON_NUM_THREADS="2", RUST_BACKTRACE="0")
    env.pop("PYTHONFAULTHANDLER", None)
    child = subprocess.Popen([sys.executable, "-c", source], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=env, cwd=REPO)
    lines: "queue.Queue[Optional[str]]" = queue.Queue()
    errors: List[str] = []

    def read_out() -> None:
        for line in child.stdout:
            lines.put(line)
        lines.put(None)

    def read_err() -> None:
        errors.append(child.stderr.read())

    readers = [threading.Thread(target=read_out, daemon=True), threading.Thread(target=read_err, daemon=True)]
    for r in readers:
        r.start()
    child.stdin.write(json.dumps(list(calls)))
    child.stdin.close()
    outcomes: Dict[int, Outcome] = {}
    running: Optional[int] = None
    timed_out = False
    while True:
        try:
            line = lines.get(timeout=timeout)
        except queue.Empty:
            timed_out = True
            child.kill()
            break
        if line is None:
            break
        message = json.loads(line)
        if "start" in message:
            running = message["start"]
        else:
            outcomes[message["end"]] = Outcome(message["kind"], message.get("detail", ""))
            running = None
    code = child.wait()
    for r in readers:
        r.join(timeout=5)
    stderr = "".join(errors)
    if running is not None:
        if timed_out:
            outcomes[running] = Outcome("timeout", f"no return within {timeout:g} s", stderr)
        elif code < 0:
            outcomes[running] = Outcome("signal", f"killed by {signal.Signals(-code).name}", stderr)
        else:
            outcomes[running] = Outcome("exit", f"exit status {code}", stderr)
    elif code != 0 and not outcomes:
        # The prelude itself failed: nothing ran.
        raise RuntimeError(f"the fuzz driver's interpreter failed before any call: {stderr[-2000:]}")
    for i, o in outcomes.items():
        if o.failed and not o.stderr:
            o.stderr = stderr
    return outcomes


def run(calls: Sequence[tuple], workers: int = 2, batch: int = BATCH,
        log=None) -> List[Finding]:
    """Runs ``calls`` (``(target name, code)``) in batches on ``workers`` interpreters at a
    time; returns the findings, each confirmed by a solo run of its call."""
    indexed = list(enumerate(calls))

    def one_batch(part: List[tuple]) -> List[Finding]:
        findings = []
        rest = part
        while rest:
            outcomes = run_batch([(i, code) for i, (_, code) in rest])
            done = 0
            for i, (name, code) in rest:
                if i not in outcomes:
                    break
                done += 1
                if outcomes[i].failed:
                    solo = run_batch([(i, code)]).get(i, Outcome("exit", "no report from the solo run"))
                    if solo.failed:
                        findings.append(Finding(code, name, solo))
                    else:
                        # Failed after the batch's earlier calls only: keep the batch's report,
                        # with the calls before it as context.
                        before = "; ".join(c for j, (_, c) in part if j < i)
                        findings.append(Finding(f"{before}; {code}", name, outcomes[i]))
                    if log:
                        log(findings[-1].report())
            rest = rest[done:]
        return findings

    parts = [indexed[k: k + batch] for k in range(0, len(indexed), batch)]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        results = list(pool.map(one_batch, parts))
    return [f for part in results for f in part]


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=int(os.environ.get("JITTERID_FUZZ_CALLS", "300")))
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--large", action="store_true", help="add values of large sizes (slow until bounded)")
    parser.add_argument("--list", action="store_true", help="list the calls, do not run them")
    parser.add_argument("--replay", metavar="CODE", help="run one call (as the reports print it) and classify it")
    a = parser.parse_args(argv)
    if a.replay:
        outcome = run_batch([(0, a.replay)])[0]
        print(f"{outcome.kind}: {outcome.detail}\n{outcome.stderr}")
        return 1 if outcome.failed else 0
    calls = draw_calls(a.seed, a.calls, large=a.large)
    if a.list:
        for name, code in calls:
            print(f"{name}: {code}")
        return 0
    findings = run(calls, workers=a.workers, log=lambda text: print(text, flush=True))
    print(f"{len(calls)} calls, {len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
