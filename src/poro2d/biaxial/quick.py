"""The quick specimen of ``poro2d biaxial --quick``: a small dense specimen made from a seed.

The paper's grading and Table 1's disks (kn = ks = 4e5 N/m, 8 mm thick) with a particle
friction of 0.5, the frictional disks of the 2D literature (docs/biaxial.md), placed by the
multilayer compaction of :mod:`poro2d.specimen.compaction` in a box twice as tall as wide
(0.05 m x 0.10 m, about 320 disks, 11 d50 wide) at a box porosity of 0.18: dense for these
disks, so it dilates in shear. A value that pickles: a worker process builds the specimen
from it, and the same seed builds the same disks, bit for bit.

A loose specimen is the same recipe built with more friction and rolling resistance while its
layers are placed (``friction_prep``, ``rolling_friction_prep``) at a looser porosity: the
preparation holds open arrangements that the working friction then keeps (docs/biaxial.md).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from poro2d.dem import Simulation
from poro2d.errors import check_int
from poro2d.grading import draw_disks
from poro2d.identity import identity_digest
from poro2d.specimen import paper_grading
from poro2d.specimen.compaction import SpecimenSpec, prepare_specimen

#: the quick specimen's box (m), porosity, friction and preparation layers
QUICK_WIDTH = 0.05
QUICK_HEIGHT = 0.10
QUICK_POROSITY = 0.18
QUICK_FRICTION = 0.5
QUICK_LAYERS = 4
#: the preparation's sliding and rolling friction unless a recipe says otherwise (SpecimenSpec's)
QUICK_FRICTION_PREP = SpecimenSpec.friction_prep
QUICK_ROLLING_PREP = SpecimenSpec.rolling_friction_prep
#: recipe fields added after quick specimens were first recorded: left out of the digest at
#: their default, so the quick specimens of earlier results keep their identity
_ADDED = {"friction_prep": QUICK_FRICTION_PREP, "rolling_friction_prep": QUICK_ROLLING_PREP}


@dataclass(frozen=True)
class QuickSpecimen:
    """The quick specimen of ``seed`` (its recipe; :meth:`simulation` builds it)."""

    seed: int = 0
    width: float = QUICK_WIDTH
    height: float = QUICK_HEIGHT
    porosity: float = QUICK_POROSITY
    friction: float = QUICK_FRICTION
    layers: int = QUICK_LAYERS
    friction_prep: float = QUICK_FRICTION_PREP
    rolling_friction_prep: float = QUICK_ROLLING_PREP

    def __post_init__(self) -> None:
        object.__setattr__(self, "seed", check_int("seed", self.seed, 0, 2**31 - 1))
        self._spec(1)  # the preparation's settings checked now, not in a worker

    @property
    def source(self) -> str:
        """How results name it: ``quick specimen (seed 3)``."""
        prep = [f"{k} {getattr(self, k):g}" for k in _ADDED if getattr(self, k) != _ADDED[k]]
        if not prep:
            return f"quick specimen (seed {self.seed})"
        return f"quick specimen (seed {self.seed}, porosity {self.porosity:g}, {', '.join(prep)})"

    @property
    def digest(self) -> str:
        """The recipe's identity (:func:`poro2d.identity.identity_digest`)."""
        recipe = {k: v for k, v in asdict(self).items() if k not in _ADDED or v != _ADDED[k]}
        return identity_digest(recipe)

    def with_seed(self, seed: int) -> QuickSpecimen:
        return replace(self, seed=seed)

    def _spec(self, threads: int) -> SpecimenSpec:
        """The preparation's settings (checked by ``SpecimenSpec``: a bad value is an InputError)."""
        return SpecimenSpec(
            width=self.width, height=self.height, layers=self.layers, friction_particle=self.friction,
            friction_prep=self.friction_prep, rolling_friction_prep=self.rolling_friction_prep,
            threads=threads,
        )  # fmt: skip

    def grains(self) -> tuple[float, np.ndarray, np.ndarray]:
        """(box width in m, radii, densities) of the specimen's disks as its preparation draws them
        (:func:`~poro2d.specimen.compaction.prepare_specimen`'s first draw; no disk placed)."""
        spec = self._spec(1)
        radii = draw_disks(paper_grading(), (1.0 - self.porosity) * self.width * self.height,
                           np.random.default_rng(self.seed))  # fmt: skip
        return self.width, radii, np.full(len(radii), spec.solid_density)

    def simulation(self, threads: int | None = None) -> Simulation:
        """The specimen, prepared now (a few seconds); refused if its preparation did not converge."""
        spec = self._spec(threads or 1)
        sim, report = prepare_specimen(spec, paper_grading(), self.porosity, seed=self.seed)
        if not report.converged:
            raise RuntimeError(f"the {self.source} did not reach equilibrium ({report.failed_stage})")
        return sim


__all__ = ["QUICK_FRICTION", "QuickSpecimen"]
