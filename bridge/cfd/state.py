"""The state of one grid's flow: the fields its next step reads, by name, with save and load to HDF5.

A :class:`FlowState` holds the Warp arrays a resumed run needs to continue bit for bit - the velocity and
pressure of :class:`bridge.cfd.Simulation` (``u``, ``v``, ``p``), and whatever a model adds: the k-omega
SST model registers ``k``, ``omega``, the flow's ``nu_eff`` (nu + nu_t, which the next step reads) and
the diffusivities of its time-step limit (``k_gamma``, ``omega_gamma``).  Stage buffers and scratch arrays
are not state (every step overwrites them before reading).  Arrays keep their storage layout, ghost
cells included (bridge.cfd.grids).

``save(group)`` writes one HDF5 dataset per field and the time and step count as attributes;
``load(group)`` assigns them back and then calls each registered ``after_load`` (a model that keeps
derived values, such as the SST model's viscous time-step limit, refreshes them there).  The aero stage's
checkpoints (bridge.aero.forced_motion) store these fields of every grid of a flow.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["FlowState"]


class FlowState:
    """Named Warp arrays of one grid (module doc), the time ``t`` and the step count ``n_steps``."""

    def __init__(self):
        self._getters: dict[str, Callable] = {}
        self._after_load: list[Callable[[], None]] = []
        self.t = 0.0
        self.n_steps = 0

    def register(self, name: str, array, after_load: Callable[[], None] | None = None) -> None:
        """Add a field: a Warp array that the step mutates in place, or a callable returning the field's
        array now (a transported scalar swaps its buffers every step, bridge.cfd.transport); ``after_load``
        runs after every load."""
        if name in self._getters:
            raise ValueError(f"the flow state already has a field {name!r}")
        self._getters[name] = array if callable(array) else (lambda: array)
        if after_load is not None and after_load not in self._after_load:
            self._after_load.append(after_load)

    @property
    def fields(self) -> dict:
        """The fields' Warp arrays as they are now, by name."""
        return {name: get() for name, get in self._getters.items()}

    def arrays(self) -> dict[str, np.ndarray]:
        """Copies of the fields on the host."""
        return {name: a.numpy().copy() for name, a in self.fields.items()}

    def assign(self, arrays: dict[str, np.ndarray]) -> None:
        """Set every field from ``arrays`` (all must be there, with the fields' shapes), then ``after_load``."""
        missing = sorted(set(self.fields) - set(arrays))
        if missing:
            raise KeyError(f"the saved state lacks the fields {missing}")
        for name, a in self.fields.items():
            values = np.asarray(arrays[name])
            if values.shape != tuple(a.shape):
                raise ValueError(f"field {name!r}: saved shape {values.shape}, this grid's {tuple(a.shape)}")
            a.assign(values)
        for hook in self._after_load:
            hook()

    def save(self, group) -> None:
        """Write the fields, ``t`` and ``n_steps`` into the (empty) HDF5 group ``group``."""
        group.attrs["t"] = float(self.t)
        group.attrs["n_steps"] = int(self.n_steps)
        for name, values in self.arrays().items():
            group.create_dataset(name, data=values)

    def load(self, group) -> None:
        """Read what :meth:`save` wrote (KeyError / ValueError if it does not fit this state)."""
        self.assign({name: group[name][()] for name in self.fields if name in group})
        self.t, self.n_steps = float(group.attrs["t"]), int(group.attrs["n_steps"])
