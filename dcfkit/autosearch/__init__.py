"""``dcfkit search``: an automated search over the component space and its parameters
(Optuna's TPE), judged on folds of sequences that did not choose (docs/search.md).

:mod:`~dcfkit.autosearch.space` reads a search spec, :mod:`~dcfkit.autosearch.evaluation` runs and
scores one config, :mod:`~dcfkit.autosearch.study` runs the studies and resumes them,
:mod:`~dcfkit.autosearch.summary` scores the held-out folds against the trackers to beat."""
from dcfkit.autosearch.space import SearchSpec, load_search_spec
from dcfkit.autosearch.study import Search, make_folds

__all__ = ["Search", "SearchSpec", "load_search_spec", "make_folds"]
