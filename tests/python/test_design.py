"""Form finding and cutting patterns through the Python package (issue 46):
``membrane_contact.design`` runs the program's ``form-find`` and ``pattern``."""

import json
import math
from pathlib import Path

import pytest

from membrane_contact.design import DesignError, form_find, pattern

CATENOID = Path(__file__).resolve().parents[2] / "examples" / "catenoid.json"
DRUM = Path(__file__).resolve().parents[2] / "examples" / "drum.json"


def _catenoid_a(r=1.0, h=1.0):
    """``a`` of the stable catenoid ``r = a cosh(z/a)`` through two rings of radius ``r`` ``h``
    apart: the larger root of ``r = a cosh(h/(2a))``, where it grows with ``a`` (``h = r``)."""
    lo, hi = 0.5 * r, r
    for _ in range(200):
        a = 0.5 * (lo + hi)
        lo, hi = (lo, a) if a * math.cosh(h / (2 * a)) > r else (a, hi)
    return 0.5 * (lo + hi)


def test_form_find_gives_the_catenoid_waist_of_the_example():
    found = form_find(CATENOID)
    waist = min(math.hypot(x, y) for x, y, _ in found["nodes"])
    a = _catenoid_a()
    assert abs(waist - 0.84668) < 1e-4, waist  # the README's golden number (32 x 16 cells)
    assert abs(waist / a - 1) < 5e-3, (waist, a)
    assert found["material"]["prestress"][:2] == json.loads(CATENOID.read_text())["material"]["prestress"][:2]


def test_pattern_cuts_the_found_catenoid_into_four_equal_strips_with_their_distortion(tmp_path):
    found = form_find(CATENOID)
    svg = tmp_path / "strips.svg"
    report = pattern(found, seam_planes=[(0, 0, 0, 1, 0, 0), (0, 0, 0, 0, 1, 0)], svg=svg)
    strips = report["strips"]
    assert len(strips) == 4 and report["erections"] == []
    assert sum(len(s["triangles"]) for s in strips) == len(found["triangles"])
    for s in strips:
        assert s["size"] == pytest.approx([1.4830, 1.0701], abs=1e-4)
        assert s["distortion"]["max"] == pytest.approx(0.08233, abs=1e-5)
        assert s["compensation"][0] == pytest.approx(0.00114, abs=1e-5)
        # The outline (the cut strip's boundary edges) spans the strip's size.
        xs, ys = ([p[c] for edge in s["outline"] for p in edge] for c in (0, 1))
        assert [max(xs) - min(xs), max(ys) - min(ys)] == pytest.approx(s["size"], abs=1e-12)
    assert svg.read_text().startswith("<svg")
    uniform = pattern(found, seam_planes=[(0, 0, 0, 1, 0, 0)], compensation=0.5)
    assert [s["compensation"] for s in uniform["strips"]] == [[0.005, 0.005]] * 2


SADDLE = Path(__file__).resolve().parents[2] / "examples" / "orthotropic_saddle.json"


def test_a_warp_target_and_geodesic_seams_pass_through_to_the_program():
    found = form_find(SADDLE, prestress=(3, 1), warp=(0.8660254, 0.5, 0))
    assert found["frame_axis"] == [0.8660254, 0.5, 0.0]
    report = pattern(found, geodesic_from=[17 * j for j in range(17)], strip_width=0.5)
    # Three seams 0.5 m apart across the 2 m square: four strips about 2 m × 0.5 m.
    assert len(report["strips"]) == 4
    for strip in report["strips"]:
        assert strip["size"][0] == pytest.approx(2.0, abs=1e-3)
        assert strip["size"][1] == pytest.approx(0.5, abs=1e-3)


def test_a_model_the_program_refuses_raises_design_error_naming_the_item():
    model = json.loads(CATENOID.read_text())
    model["material"]["thickness"] = -1.0
    with pytest.raises(DesignError, match="thickness"):
        form_find(model)
    with pytest.raises(DesignError, match="seam"):
        pattern(json.loads(CATENOID.read_text()), seam_nodes=[[0, 10 ** 9]])


def test_by_element_erections_over_the_drum_with_friction_name_what_friction_holds():
    """The drum of ``examples/drum.json`` (μ = 0.3) cut in one strip: the element-wise correction
    cannot bring the crown to its prestress (friction sets it, not the cut) and says so; with the
    friction taken off, one correction brings every element away from the rails within 0.5 %."""
    report = pattern(DRUM, erect=3, by_element=True)
    erections = report["erections"]
    assert len(erections) == 3 and erections[-1]["max_error"] > 0.1
    # Each erection's stresses give its largest error away from the rails.
    drum = json.loads(DRUM.read_text())
    rails = {v for g in drum["groups"] for v in g["nodes"]}
    for e in erections:
        errors = [max(abs(s[0] - 2e6), abs(s[1] - 2e6)) / 2e6
                  for t, s in zip(drum["triangles"], e["stress"]) if not rails & set(t)]
        assert len(e["stress"]) == len(drum["triangles"])
        assert max(errors) == pytest.approx(e["max_error"], rel=1e-12)
    assert set(report["held_by_friction"]) <= set(report["stalled"]) and report["held_by_friction"]
    frictionless = json.loads(DRUM.read_text())
    frictionless["curved_supports"][0]["friction"] = 0.0
    report = pattern(frictionless, compensation=0, erect=3, by_element=True, erect_tolerance=0.5)
    errors = [e["max_error"] for e in report["erections"]]
    assert errors[0] == pytest.approx(1.0) and len(errors) == 2 and errors[1] < 0.005, errors
    assert report["stalled"] == [] and report["held_by_friction"] == []


def test_settle_auto_and_the_contact_stiffness_reach_the_program_and_come_back_in_the_report():
    """``settle="auto"``: the program chooses the amplitude (``--settle auto``) and reports it with
    ``chosen``; the same amplitude given explicitly erects the same film. The drum's film touches
    it over an area, so its penalties stay per node (``tributary_length`` None) and
    ``contact_stiffness="per-length"`` is refused naming it."""
    options = dict(erect=1, by_element=True, rail_path=(0.10, 0.03))
    auto = pattern(DRUM, settle="auto", **options)
    settle = auto["settle"]
    assert settle["chosen"] is True and (settle["ratio"], settle["cycles"]) == (0.7, 12)
    given = pattern(DRUM, settle=(settle["amplitude"], 0.7, 12), **options)
    assert given["settle"]["chosen"] is False
    assert given["erections"][0]["stress"] == auto["erections"][0]["stress"]
    # 5.48 % (5.64 % with the path followed in 40 increments: tests/patterning.rs), 21 % unsettled
    assert auto["erections"][0]["max_error"] < 0.06
    stiffness = auto["contact_stiffness"]
    assert stiffness[0]["support"] == "drum" and stiffness[0]["tributary_length"] is None
    with pytest.raises(DesignError, match="'drum'"):
        pattern(DRUM, contact_stiffness="per-length", **options)


def _vault_bay():
    import importlib.util
    path = Path(__file__).resolve().parents[2] / "examples" / "vault_bay.py"
    spec = importlib.util.spec_from_file_location("vault_bay", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_vault_bay_erects_to_its_prestress_without_friction_and_names_what_friction_holds_with_it(capsys):
    """The issue's vault bay (``examples/vault_bay.py``): found against its arches and ridge,
    cut in eight strips. Frictionless, the prestress compensation erects within 0.5 % of 1.5 MPa
    away from the rails (0.29 %); with μ = 0.3 it misses by 13 %, the per-element correction
    does not bring it within 5 %, and every triangle left outside is held by friction; none
    yields (ETFE's data-sheet hardening, first yield 21 MPa)."""
    bay = _vault_bay()
    _, (uniform, _) = bay.main(mu=0.0, paths=((None, 10, None),))
    assert uniform["erections"][0]["max_error"] < 5e-3, uniform["erections"][0]
    _, (uniform, element, uniform_path, element_path) = bay.main(paths=((None, 10, None), ((0.10, 0.03), 40, None)))
    assert uniform["erections"][0]["max_error"] > 0.1
    last = element["erections"][-1]
    assert last["max_error"] > 0.05 and last["outside_tolerance"] > 0 and last["yielded"] == 0
    assert element["held_by_friction"] and set(element["held_by_friction"]) == set(element["stalled"])
    assert "held by friction" in capsys.readouterr().out
    # The issue's path (rails pulled down 0.10 m and out 0.03 m): no better.
    assert uniform_path["erections"][0]["max_error"] > 0.1
    last = element_path["erections"][-1]
    assert last["max_error"] > 0.05 and last["outside_tolerance"] > 0 and last["yielded"] == 0
    assert element_path["held_by_friction"] and set(element_path["held_by_friction"]) == set(element_path["stalled"])


def test_vault_bay_settled_on_the_issues_path_carries_1_5_mpa_within_5_percent_away_from_the_rails_and_none_yields():
    """The issue's must-show: the vault bay (mu = 0.3), eight strips with the prestress
    compensation, rails down 0.10 m and out 0.03 m. On that path alone every contact node off the
    crown ends sliding and the stress away from the rails misses 1.5 MPa by 14 %; settled
    (``examples/vault_bay.py``'s ``SETTLE``: the rails then pass their places by 1 mm and come back
    in 12 waypoints shrinking by 0.7), every contact node sticks and every triangle away from the
    rails carries 1.5 MPa +- 5 % in both directions, none yielded. The figure's CSV keeps the
    settled largest error as its golden number (3.12 %), computed as here: 40 increments a leg."""
    bay = _vault_bay()
    found = form_find(bay.vault_bay(), on_supports=True)
    seams = [(0, bay.BAY * k / 8, 0, 0, 1, 0) for k in range(1, 8)]
    rails = {v for g in found["groups"] for v in g["nodes"]}
    away = [not rails & set(t) for t in found["triangles"]]
    end = {}
    for name, settle in (("alone", None), ("settled", bay.SETTLE)):
        end[name] = pattern(found, seam_planes=seams, erect=1, erect_tolerance=5.0, by_element=True,
                            rail_path=(0.10, 0.03), erect_increments=40, settle=settle)["erections"][0]
    statuses = lambda e: [c["status"] for c in e["contacts"]]
    largest = lambda e: max(max(abs(s[0] - 1.5e6), abs(s[1] - 1.5e6)) / 1.5e6
                            for s, a in zip(e["stress"], away) if a)
    assert largest(end["alone"]) > 0.10 and statuses(end["alone"]).count("Slip") == 110
    settled = end["settled"]
    assert largest(settled) < 0.05 and settled["max_error"] == pytest.approx(largest(settled), rel=1e-12)
    assert settled["outside_tolerance"] == 0 and settled["yielded"] == 0
    assert statuses(settled) == ["Stick"] * 119
    root = Path(__file__).resolve().parents[2]
    golden = [r for r in (root / "docs" / "figures" / "design_iterations.csv").read_text().splitlines()
              if r.startswith('"vault, rails down and out, settled, per element",0,')][0]
    assert float(golden.split(",")[-1]) == pytest.approx(settled["max_error"], abs=1e-6)


def test_vault_bay_contact_nodes_off_the_crown_end_sliding_at_mu_n_whatever_the_rail_path():
    """Why the vault bay's end state does not depend on its erection path (the drum's does): on
    the straight path (rails down 0.10 m and out 0.03 m together) and both winding ones (down then
    out, out then down), every contact node off the crown ends sliding towards its rail, its
    friction force μN pointing to the crown (along the arch: the rings' ξ1 grows eastwards) and
    none across; the crown's nodes (arches and ridge) stick with almost no tangential force (the
    bay is symmetric). A sliding node carries μN whatever came before, so the end state is the
    end's alone: the three paths' stresses agree within 1e-5 of the target."""
    bay = _vault_bay()
    found = form_find(bay.vault_bay(), on_supports=True)
    seams = [(0, bay.BAY * k / 8, 0, 0, 1, 0) for k in range(1, 8)]
    stresses = []
    for path in ([(0.10, 0.03)], [(0.10, 0.03), (0.0, 0.03)], [(0.10, 0.03), (0.10, 0.0)]):
        erection = pattern(found, seam_planes=seams, erect=1, by_element=True, rail_path=path,
                           erect_increments=20)["erections"][0]
        contacts = erection["contacts"]
        assert len(contacts) == 119
        for c in contacts:
            x, f = found["nodes"][c["node"]][0], math.hypot(*c["friction"])
            if abs(x) < 1e-9:
                assert c["status"] == "Stick" and f < 0.05 * bay.MU * c["normal_force"], c
            else:
                assert c["status"] == "Slip" and f == pytest.approx(bay.MU * c["normal_force"], rel=1e-9), c
                assert c["friction"][0] * x < 0 and abs(c["friction"][1]) < 1e-3 * f, c
        assert sum(abs(found["nodes"][c["node"]][0]) < 1e-9 for c in contacts) == 9
        stresses.append(erection["stress"])
    for other in stresses[1:]:
        apart = max(abs(p - q) for u, v in zip(other, stresses[0]) for p, q in zip(u, v))
        assert apart < 1e-5 * 1.5e6, apart


def test_design_iterations_figure_drum_rows_match_its_csv_golden_number():
    """``examples/design_iterations.py``: its drum rows (computed again here) give the golden
    number of ``docs/figures/design_iterations.csv``: the largest error of the first erection over
    the drum with mu = 0.3, 17.8791 %, and the frictionless drum reaches 0.375 % in one correction."""
    import importlib.util
    root = Path(__file__).resolve().parents[2]
    spec = importlib.util.spec_from_file_location("design_iterations", root / "examples" / "design_iterations.py")
    fig = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fig)
    rows = {(r[0], r[1]): r[3] for r in fig.drum_rows()}
    assert rows[("drum, mu = 0.3, prestress compensation", 0)] == pytest.approx(0.178791, abs=1e-5)
    assert rows[("drum, mu = 0, uncompensated start", 1)] == pytest.approx(0.003750, abs=1e-5)
    golden = [r for r in (root / "docs" / "figures" / "design_iterations.csv").read_text().splitlines()
              if r.startswith("\"drum, mu = 0.3") or r.startswith("drum, mu = 0.3")][0]
    assert float(golden.split(",")[-1]) == pytest.approx(0.178791, abs=1e-5)


def test_pattern_variants_on_the_study_cluster_give_each_variants_own_report():
    """Two compensation variants of the drum (μ = 0.3), the rails straight down and out and the
    winding path (down, then out), and one the program refuses, run on a local Dask cluster of two
    workers: each report is the one :func:`pattern` gives alone, the paths differ (friction), and
    the refused variant carries the program's message while the others go on."""
    pytest.importorskip("distributed")
    from membrane_contact.design import pattern_variants

    straight = dict(erect=1, by_element=True, rail_path=(0.10, 0.03))
    winding = dict(erect=1, by_element=True, rail_path=[(0.10, 0.03), (0.0, 0.03)])
    refused = dict(erect=0, by_element=True)
    reports = pattern_variants(DRUM, [straight, winding, refused], workers=2)
    assert "--erect" in reports[2]["error"]
    for options, report in zip((straight, winding), reports):
        alone = pattern(DRUM, **options)
        assert report["erections"] == alone["erections"]
    first = [r["erections"][0]["max_error"] for r in reports[:2]]
    assert abs(first[0] - first[1]) > 1e-3, first


def test_each_erection_model_of_the_compensation_is_written_for_a_study(tmp_path):
    """``erection_models``: one model per erection of the loop, as it was erected, each a model
    the program accepts (``membrane-contact check``) and so one a study can pack and run."""
    report = pattern(DRUM, erect=2, by_element=True, erection_models=tmp_path)
    files = sorted(tmp_path.glob("erection-*.json"))
    assert [f.name for f in files] == [f"erection-{k}.json" for k in range(len(report["erections"]))]
    from membrane_contact.design import _run
    for f in files:
        _run(["check", str(f)])
