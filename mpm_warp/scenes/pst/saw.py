"""The PST's saw and front criteria (:class:`Saw`, :class:`Front`) and where a saw that stops on runaway stopped.

With ``saw.stop = "runaway"`` (the field protocol) the blade advances towards ``saw.cut_length`` and stops where
it is once the damage front leads it by ``front.runaway_lead``, as an observer stops sawing once the crack runs
away: what follows is the crack's own. The monitor (:class:`~mpm_warp.scenes.pst.PSTMonitor`) finds the runaway
at a frame and writes the blade's position then into the 1-element device array the saw kernel reads as the
blade's end (:mod:`mpm_warp.scenes.weak_layer.kernels`). A run whose saw stopped at ``a`` is a run whose saw was
set to cut ``a`` (:func:`sawn`): every analysis that recomputes the blade's position from its speed and the time
(runaway cut, classification, speeds, plots) takes the parameters of the cut made.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["Saw", "Front", "CutFrom", "SawStop", "sawn", "blade_position", "blade_time", "stop_record"]

#: where the saw starts: the column's upslope or downslope end (on flat ground "upslope" is the end x = 0)
CutFrom = Literal["upslope", "downslope"]
#: where the blade stops: at ``saw.cut_length``, or once the crack runs away from it (the field protocol)
SawStop = Literal["cut_length", "runaway"]


@dataclass(frozen=True)
class Saw:
    """The saw: a blade advancing through the weak layer from one end of the column after settling.

    Behind the blade the weak layer loses its bond (a kerf): cohesionless, it collapses under the
    slab as a debonded layer does (:mod:`mpm_warp.scenes.weak_layer`).

    Attributes
    ----------
    speed : float
        Blade speed (m/s), in (0, 1]: a saw is slow against the crack (field saws: 0.1-0.5 m/s).
    cut_length : float
        Length of the cut (m), in [0, length], along the weak layer from the end it starts at: the end the
        blade may go to (with ``stop = "runaway"`` the column's end for a field test, as an observer saws on
        until the crack runs away).
    cut_from : {"upslope", "downslope"}
        The end of the column it starts from. ``x`` runs downslope, so on a slope of positive angle the
        upslope end is ``x = 0``; on flat ground "upslope" names the end ``x = 0``.
    pre_cut : float
        Length already cut when the run starts (m), in [0, cut_length]: the kerf is there from t = 0, through
        the settling, and the blade advances from it at ``speed`` once settling ends. Elastic and bonded short
        of the critical cut, a column pre-cut to ``pre_cut`` settles into the state a slow saw leaves there,
        without the simulated time of sawing it (docs/model.md §6). 0 (the default): the saw cuts from the end.
    stop : {"cut_length", "runaway"}
        Where the blade stops: "cut_length", at ``cut_length`` (the default); "runaway", where it is at the
        first frame the damage front leads it by ``front.runaway_lead`` (the field protocol: what follows is the
        crack's own), or at ``cut_length`` if the crack never runs away (a "no propagation" outcome, NP). The run
        records where it stopped (``saw_stopped_at``, m from the cut end).
    """

    speed: float = 1.0
    cut_length: float = 0.6
    cut_from: CutFrom = "upslope"
    pre_cut: float = 0.0
    stop: SawStop = "cut_length"


@dataclass(frozen=True)
class Front:
    """The front criteria (see :mod:`mpm_warp.scenes.pst`).

    Attributes
    ----------
    bin : float
        Bin width along the column (m); 0 = the grid spacing.
    deflection : float
        The slab-deflection front: the slab base has come down by this fraction of the collapse
        height ``h_c`` (-), in (0, 1].
    runaway_lead : float
        The crack runs away from the saw once the damage front leads the blade by this (m), > 0:
        the saw position then estimates the critical cut from one run (and a saw with ``stop =
        "runaway"`` stops there).
    """

    bin: float = 0.0
    deflection: float = 0.1
    runaway_lead: float = 0.3


def sawn(params, stopped_at: float = math.nan):
    """The parameters of the cut made: ``params`` (a :class:`~.params.PSTParams`, which imports this module) with
    ``saw.cut_length`` the blade's stop ``stopped_at`` (m from
    the cut end) when it stopped on runaway (finite), ``params`` itself otherwise.

    The blade's history is that of a saw set to cut ``stopped_at``, so the analyses that recompute it from its
    speed and the time (:func:`blade_position`, ``saw_end``, the runaway cut, the class) take these.
    """
    if not math.isfinite(stopped_at):
        return params
    return dataclasses.replace(params, saw=dataclasses.replace(params.saw, cut_length=float(stopped_at)))


def blade_position(params, t):
    """Blade distance from the cut end (m) at times ``t`` (s; float or array): ``pre_cut + speed (t - saw_start)``
    within ``[pre_cut, saw.cut_length]`` (pass :func:`sawn` parameters for a saw that stopped on runaway)."""
    s = params.saw
    moved = s.speed * np.maximum(np.asarray(t, dtype=float) - params.saw_start, 0.0)
    return np.minimum(s.pre_cut + moved, s.cut_length)


def blade_time(params, position: float) -> float:
    """Time (s) the blade reaches ``position`` (m from the cut end): the end of settling for any position within
    the pre-cut, ``saw_start + (position - pre_cut) / speed`` beyond it."""
    s = params.saw
    return params.saw_start + max(float(position) - s.pre_cut, 0.0) / s.speed


def stop_record(params, stopped_at: float, runaway: float) -> dict:
    """``saw_stopped_at`` (m from the cut end, nan: it did not stop on runaway) with the reason under
    ``saw_stopped_at_null`` when nan, for a run file.

    Parameters
    ----------
    params : PSTParams
        The scene's parameters (not :func:`sawn`).
    stopped_at : float
        Where the monitor stopped the blade (m; nan: it did not).
    runaway : float
        The run's runaway cut (m; nan: the crack has not run away).
    """
    if math.isfinite(stopped_at):
        return {"saw_stopped_at": float(stopped_at)}
    out = {"saw_stopped_at": math.nan}       # the one nan object: records compare equal as dicts
    if params.saw.stop != "runaway":
        why = 'saw.stop = "cut_length": the blade goes to saw.cut_length'
    elif math.isfinite(runaway):
        why = "the crack ran away only once the blade had reached saw.cut_length"
    else:
        why = f"the damage front has not led the blade by front.runaway_lead = {params.front.runaway_lead:g} m"
    out["saw_stopped_at_null"] = why
    return out
