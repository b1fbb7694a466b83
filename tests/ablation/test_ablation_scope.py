"""Every output of an ablation names the experiment it scored, its protocol and a --max-frames cut."""
from __future__ import annotations

import json

from test_ablation import data, write_spec  # noqa: F401  (the synthetic OTB folder)

from dcfkit import cli
from dcfkit.ablation import summary as ablation_summary
from dcfkit.analysis.plots import plot_title


def test_plot_titles_name_the_experiment():
    assert plot_title("success") == "Success plots of OPE"
    assert plot_title("precision", "tre") == "Precision plots of TRE"


def test_an_sre_smoke_ablation_names_its_experiment_and_cut_everywhere(tmp_path, data, monkeypatch,  # noqa: F811
                                                                       capsys):
    titles = []
    plot = ablation_summary.plot_curves

    def recorded(curves, kind, stem, title=None, **kwargs):
        titles.append(title)
        return plot(curves, kind, stem, title=title, **kwargs)

    monkeypatch.setattr(ablation_summary, "plot_curves", recorded)
    spec = write_spec(tmp_path / "spec.yaml", "name: scoped\ndataset: {name: otb, root: data}\n"
                                              "variants: {k: {config: kcf}}\n")
    out = tmp_path / "out"
    assert cli.main(["ablate", str(spec), "--out", str(out), "--sequences", "seqA", "--jobs", "1", "--no-progress",
                     "--experiment", "sre", "--max-frames", "6"]) == 0
    printed = capsys.readouterr().out
    scope = "experiment SRE (spatial robustness"
    cut = "first 6 frames (--max-frames 6)"
    assert printed.startswith(f"scoped: {scope}") and cut in printed.splitlines()[0]
    summary = (out / "summary.md").read_text().splitlines()
    assert summary[0].startswith(f"# scoped: {scope}") and "protocol otb" in summary[0] and cut in summary[0]
    assert (out / "per_sequence.md").read_text().startswith(f"# scoped: {scope}")
    assert (out / "statistics.txt").read_text().startswith(scope)
    assert titles == ["Precision plots of SRE, first 6 frames (--max-frames 6)",
                      "Success plots of SRE, first 6 frames (--max-frames 6)"]
    record = json.loads((out / "summary.json").read_text())
    assert record["experiment"] == "sre" and record["max_frames"] == 6 and record["scope"].startswith(scope)
    page = (out / "report.html").read_text()
    assert "scoped: 1 variant on otb, SRE, first 6 frames (--max-frames 6)</h1>" in page
    assert "Success plots of SRE" in page and "plots of OPE" not in page
