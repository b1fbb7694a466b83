"""The result store, below both running and analysis: result files that cannot be silently
damaged (:mod:`~dcfkit.store.results`, :mod:`~dcfkit.store.files`), claims on the runs of a
folder (:mod:`~dcfkit.store.claims`), what produced a result (:mod:`~dcfkit.store.provenance`,
:mod:`~dcfkit.store.code_state`, :mod:`~dcfkit.store.platforms`) and how its speed was measured
(:mod:`~dcfkit.store.timing`). The runner writes through it and scoring reads through it; neither
imports the other."""
