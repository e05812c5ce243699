"""Pareto front of study settings (every objective minimised): see ladartui.pareto."""

from ladartui.pareto import dominates, dominator, pareto_front

__all__ = ["dominates", "dominator", "pareto_front"]
