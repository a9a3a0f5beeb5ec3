"""Falsification: search a box of context parameters for the worst case (issue 28).

``space`` (the box), ``objective`` (a metric, or the robustness of ``expect``), ``search``
(Latin hypercube then CMA-ES, each generation one batch through ``runs.evaluate``) and
``outputs`` (results.csv, worst.yaml); ``cli/falsify.py`` drives them.
"""
