"""Choosing a design: k-ε optimality (:mod:`.kepsilon`, Sec 6.1.1), the run behind
``suspopt kesort`` (:mod:`.selection`: Pareto sets read, re-evaluated, pooled and sorted),
the picks that name designs across result files (:mod:`.picks`), and the values of designs
as built (:mod:`.builds_file`: an ``analyse builds`` file read back for ``kesort --builds``
and ``--as-built``)."""
