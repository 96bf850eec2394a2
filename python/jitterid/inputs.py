"""Known inputs: piecewise constant (edges and levels, zero-order hold, a seeded random
binary realisation), a sine and a multisine, as the library's inputs."""

from __future__ import annotations

from typing import Any, Optional

from . import _jitterid
from ._spec import integer, real_number

__all__ = ["Input", "piecewise", "zero_order_hold", "random_binary", "sine", "multisine"]


class Input(_jitterid.Input):
    """A known input ``u(t)``; ``value(t)`` evaluates it."""

    def __reduce__(self) -> Any:
        return (Input, (self.to_json(),))


def _wrap(x: _jitterid.Input) -> Input:
    return Input(x.to_json())


def piecewise(edges: Any, levels: Any) -> Input:
    """``u = levels[j]`` on ``[edges[j], edges[j+1])``, zero outside (one more edge than levels)."""
    return _wrap(_jitterid.Input.piecewise(edges, levels))


def zero_order_hold(values: Any, interval: float, start: float = 0.0) -> Input:
    """``u = values[k]`` on ``[start + k·interval, start + (k+1)·interval)``."""
    return _wrap(_jitterid.Input.zero_order_hold(values, real_number(interval, "interval"),
                                                 real_number(start, "start")))


def random_binary(start: float, end: float, seed: int, mean_dwell: float = 8.0, low: float = 0.0,
                  high: float = 1.0) -> Input:
    """A realisation on ``[start, end)`` of the random binary input (exponential dwell times of
    mean ``mean_dwell``, levels ``low``/``high``) from a generator seeded with ``seed``."""
    return _wrap(_jitterid.Input.random_binary(real_number(start, "start"), real_number(end, "end"),
                                               integer(seed, "seed"), real_number(mean_dwell, "mean_dwell"),
                                               real_number(low, "low"), real_number(high, "high")))


def sine(frequency: float, amplitude: float = 1.0, phase: float = 0.0) -> Input:
    """``amplitude · sin(2π·frequency·t + phase)``."""
    return multisine([real_number(frequency, "frequency")], [real_number(amplitude, "amplitude")],
                     [real_number(phase, "phase")])


def multisine(frequencies: Any, amplitudes: Optional[Any] = None, phases: Optional[Any] = None) -> Input:
    """``Σ A_l sin(2πf_l t + φ_l)`` (amplitudes 1, phases 0 by default)."""
    return _wrap(_jitterid.Input.multisine(frequencies, amplitudes, phases))
