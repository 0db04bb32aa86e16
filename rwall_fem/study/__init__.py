"""What accuracy costs in time: a convergence and cost study against independent references.

:mod:`~rwall_fem.study.cases` (the scenes and their exact answers),
:mod:`~rwall_fem.study.runner` (the runs) and :mod:`~rwall_fem.study.report` (costs,
tables, plots). ``rwall-fem study`` runs it; ``make study`` copies its report into docs/.
"""

from rwall_fem.study.cases import CASES, Case
from rwall_fem.study.report import cost_at
from rwall_fem.study.runner import run_study

__all__ = ["CASES", "Case", "cost_at", "run_study"]
