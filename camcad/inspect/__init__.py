"""Tolerances and inspection of a made cam (issue 38): Monte Carlo, allocation, CMM points against the design.

Sits between dynamics and fit (see tests/test_architecture.py): it needs the
exact envelope and the motion, and a compensated profile is what the fit and
the tool path will later take. Nothing here reads files or the design schema.
"""

from __future__ import annotations

__all__: list[str] = []
