"""``lawbench measurements``: the sets of measured impacts, with count, source and licence."""

import re

from lawbench.views.cli import main


def test_the_listing_names_every_set_with_its_count_source_and_licence(capsys):
    """Counts as the shipped conversions keep them (each set's README): 1718 unflagged bounces
    of Fazeli et al.'s 2000, 348 clean first impacts of the 550 ContactNets tosses, and the
    Kharaz points within the digitized spin's range."""
    assert main(["measurements"]) == 0
    out = capsys.readouterr().out
    counts = dict(re.findall(r"^(\w+)\s+(\d+) impacts", out, flags=re.M))
    assert counts == {"cube": "348", "ellipse": "1718", "kharaz": "6"}
    assert out.count("licence: ") == 3 and out.count("source:  ") == 3
    assert "Fazeli" in out and "Kharaz" in out and "ContactNets" in out


def test_one_set_shows_its_processing_and_self_consistency(capsys):
    assert main(["measurements", "ellipse"]) == 0
    out = capsys.readouterr().out
    assert "kept:        1718" in out and "corrected:" in out
    assert re.search(r"consistency: .* median 0\.02\d*", out)


def test_an_unknown_set_is_refused_by_name(capsys):
    assert main(["measurements", "nope"]) == 2
    assert "unknown measurement set 'nope'" in capsys.readouterr().err
