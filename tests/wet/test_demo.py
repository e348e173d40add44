import pytest

from clutchlab.report import Figure, Section, Table


def test_demo_section_compares_identified_with_true():
    from clutchlab.demo.wet import demo_section

    messages = []
    sec = demo_section(messages.append)
    assert isinstance(sec, Section) and "synthetic" in sec.provenance
    assert messages
    figs = [i for i in sec.items if isinstance(i, Figure)]
    tables = {i.name: i.frame for i in sec.items if isinstance(i, Table)}
    assert {"wet_fig13_traces", "wet_fig14_engagement", "wet_fig15_map"} <= {f.name for f in figs}
    k = tables["wet_thermal"]
    for _, row in k.iterrows():
        assert row["identified"] == pytest.approx(row["true (Table 1)"], rel=0.03)
    law = tables["wet_law"]
    for _, row in law.iterrows():
        assert row["identified"] == pytest.approx(row["true (bench)"], rel=0.05)
    import matplotlib.pyplot as plt

    for f in figs:
        plt.close(f.figure)
