"""The paper's criterion (its Fig. 3) for the final 2D porosity."""

from poro2d.criterion.protocol import CriterionSettings, PorosityCriterion
from poro2d.criterion.run import CriterionCase, run_criterion

__all__ = ["CriterionCase", "CriterionSettings", "PorosityCriterion", "run_criterion"]
