"""Statistics as typed results (:mod:`~dcfkit.analysis.stats.results`) and the one declaration of
how each shows in every output (:mod:`~dcfkit.analysis.stats.columns`); computed by
:mod:`dcfkit.analysis.statistics` (docs/evaluation.md, "Statistics")."""
