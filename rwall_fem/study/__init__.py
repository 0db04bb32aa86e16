"""What accuracy costs in time: a convergence and cost study against independent references.

:mod:`~rwall_fem.study.cases` (the scenes and their exact answers),
:mod:`~rwall_fem.study.runner` (the runs) and :mod:`~rwall_fem.study.report` (costs,
tables, plots); :mod:`~rwall_fem.study.shells`, shells against solids on a struck plate
(``rwall-fem study --shells``). ``rwall-fem study`` runs it; ``make study`` copies its
report into docs/.
"""

from rwall_fem.study.cases import CASES, Case
from rwall_fem.study.report import cost_at
from rwall_fem.study.runner import run_study
from rwall_fem.study.shells import run_shell_study

__all__ = ["CASES", "Case", "cost_at", "run_shell_study", "run_study"]
