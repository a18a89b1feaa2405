"""The time-varying fields of a run on the device: particle positions, velocities, deformation and clock.

:class:`State` allocates only the fields a scene needs (``log_jp`` and ``hzz`` only for Cam-Clay
particles, ``kappa`` only for softening ones, ``yielded`` only when the output asks for it) and
copies them to and from the host for checkpoints and snapshots. The static description it is
built from is the :class:`~mpm_warp.model.Model`.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from .errors import InvalidArgument
from .kernels.types import mat, vec

__all__ = ["State"]


class State:
    """Time-varying fields on the device (``dim``-vectors and ``dim x dim`` matrices).

    Attributes
    ----------
    x, v : wp.array of vec, (N,)
        Position (m) and velocity (m/s).
    C : wp.array of mat, (N,)
        APIC/MLS affine velocity matrix (1/s).
    H : wp.array of mat, (N,)
        Elastic displacement gradient ``F_E - I`` (-), in-plane block in 2D (see
        ``kernels/constitutive.py``: stored as ``F_E - I`` so that float32 keeps
        increments far below its resolution of 1).
    hzz : wp.array, (N_plastic,) or None
        Out-of-plane elastic stretch minus one, ``F_E,zz - 1`` (-), of the plastic particles in plane strain
        (indexed as ``log_jp``); an elastic particle's ``F_E,zz`` is the total, 1, and is not stored.
    log_jp : wp.array, (N_plastic,) or None
        ln det F_P of Cam-Clay particles.
    kappa : wp.array, (N_kappa,) or None
        The softening state of the bonded weak-layer particles (plastic work, J/m^3; the first plastic ones)
        and then of the cracking ones (largest effective tensile stress, Pa), indexed by ``kappa_start``.
    yielded : wp.array of uint8, (N_plastic,) or None
        Return-mapping activity flag, only when the output asks for it.
    clock : wp.array of float64, (4,)
        ``[t, dt, t_end, dt_last]`` (s).
    steps : wp.array of int64, (1,)
        Steps taken.
    """

    #: the arrays a checkpoint holds (those that exist; ``yielded`` holds the flags of a frame stopped half-way)
    CHECKPOINT_FIELDS = ("x", "v", "C", "H", "hzz", "log_jp", "kappa", "yielded", "clock", "steps")

    def __init__(self, model, x, v, C, log_jp, kappa, track_yield: bool):
        """The fields of ``model`` (a :class:`~mpm_warp.model.Model`) from its host arrays at t = 0."""
        dev = model.device
        T = model.T
        d = model.dim
        V, M = vec(d, T), mat(d, T)
        n = len(x)
        self.model = model
        self.x = wp.array(x, dtype=V, device=dev)
        self.v = wp.array(v.astype(model.np_dtype), dtype=V, device=dev)
        self.C = wp.array(C, dtype=M, device=dev)
        self.H = wp.zeros(n, dtype=M, device=dev)
        self.hzz = wp.zeros(model.n_plastic, dtype=T, device=dev) if d == 2 and model.n_plastic else None
        self.log_jp = wp.array(log_jp, dtype=T, device=dev) if model.n_plastic else None
        self.kappa = wp.array(kappa, dtype=T, device=dev) if model.n_kappa else None
        track = track_yield and model.n_plastic > 0
        self.yielded = wp.zeros(model.n_plastic, dtype=wp.uint8, device=dev) if track else None
        self.clock = wp.zeros(4, dtype=wp.float64, device=dev)
        self.steps = wp.zeros(1, dtype=wp.int64, device=dev)

    def particle_bytes(self) -> int:
        """Bytes held by per-particle arrays on the device."""
        arrs = [self.x, self.v, self.C, self.H, self.hzz, self.log_jp, self.kappa, self.yielded]
        return sum(a.capacity for a in arrs if a is not None)

    def elastic_deformation_gradient(self) -> np.ndarray:
        """Host copy of ``F_E`` as (N, 3, 3) float64 (in 2D: the in-plane block and ``F_zz``)."""
        H = self.H.numpy().astype(np.float64)
        n, d = H.shape[0], H.shape[1]
        F = np.zeros((n, 3, 3))
        F[:, :d, :d] = H
        F[:, range(3), range(3)] += 1.0
        if self.hzz is not None:
            hzz = self.hzz.numpy().astype(np.float64)
            for g in self.model.groups:
                if g.plastic_start >= 0:
                    F[g.start:g.end, 2, 2] += hzz[g.plastic_start:g.plastic_start + g.count]
        return F

    def set_elastic_deformation_gradient(self, F) -> None:
        """Set ``F_E`` from (N, 3, 3) (in 2D only the in-plane block and ``F_zz`` are used; computed as
        ``F - I`` in float64 before rounding to the state's precision)."""
        F = np.asarray(F, dtype=np.float64)
        d = self.model.dim
        H = F[:, :d, :d] - np.eye(d)
        self.H.assign(H.astype(self.model.np_dtype))
        if d == 2:
            hzz = np.zeros(self.model.n_plastic)
            for g in self.model.groups:
                zz = F[g.start:g.end, 2, 2] - 1.0
                if g.plastic_start >= 0:
                    hzz[g.plastic_start:g.plastic_start + g.count] = zz
                elif np.any(zz != 0.0):
                    raise InvalidArgument(f"F[{g.start}:{g.end}, 2, 2] (group {g.name!r}, elastic, plane strain)",
                                          float(F[g.start + int(np.argmax(zz != 0.0)), 2, 2]),
                                          "1 (an elastic particle's out-of-plane stretch is the total one)")
            if self.hzz is not None:
                self.hzz.assign(hzz.astype(self.model.np_dtype))

    def arrays(self) -> dict[str, np.ndarray]:
        """Host copies of the full state (checkpoints, snapshots): copies, never views of the device
        memory (on the CPU ``wp.array.numpy()`` is a view, which the next step would overwrite)."""
        d = {}
        for k in self.CHECKPOINT_FIELDS:
            a = getattr(self, k)
            if a is not None:
                d[k] = np.array(a.numpy(), copy=True)
        return d

    def load_arrays(self, d: dict[str, np.ndarray]) -> None:
        """Restore the state from :meth:`arrays` output (bit for bit)."""
        for k in self.CHECKPOINT_FIELDS:
            dst = getattr(self, k)
            if dst is None or (k == "yielded" and k not in d):   # older checkpoints hold no yielded flags
                continue
            a = np.asarray(d[k])
            if k == "hzz" and a.shape[0] != dst.shape[0]:    # an older checkpoint: hzz of every particle
                a = np.concatenate([a[g.start:g.end] for g in self.model.groups if g.plastic_start >= 0])
            if k == "clock" and a.shape[0] < dst.shape[0]:  # a 3-entry clock of an older checkpoint
                a = np.concatenate([a, [a[1]]])
            dst.assign(a)
