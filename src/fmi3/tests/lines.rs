//! The per-line arrays of the FMI 3.0 interface (issue 45 item 3) against the VTK film file.
//!
//! TEST GOAL: every reaction line's `<line>.lineReaction` and `<line>.linePosition` equal, to
//! the last bit, the VTK film file's `line_reaction` field and points at the line's nodes, in
//! the line's order (where lines meet, their shares add up to the field, in the file's order of
//! summation), `<line>.lineArc` is the line's arc length, and `<line>.linePoints` sizes them.
//!
//! MODEL: `examples/hinged_panel.json`: the hinged group `rail` and the support set `frame`,
//! two lines that share their corner nodes.
//!
//! BOUNDARY CONDITIONS: `rail.dz` to −0.01 m and `rail.angle` to 0.02 rad over two steps.
//!
//! PARAMETERS: the model's; VTK output as text (`results.vtkFormat = ascii`, floats written to
//! round-trip).

use super::*;
use crate::fmi3::arrays::{Arrays, Field};
use crate::mech::Model;
use crate::mech::results::lines::reaction_lines;

/// The values of the `DataArray` that follows `after` in the ascii VTK file `xml`.
fn data_array(xml: &str, after: &str) -> Vec<f64> {
    let at = xml.find(after).unwrap_or_else(|| panic!("no {after}"));
    let body = &xml[at..];
    let tag = "format=\"ascii\">";
    let start = body.find(tag).unwrap() + tag.len();
    let end = start + body[start..].find("</DataArray>").unwrap();
    body[start..end]
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect()
}

#[test]
fn fmi3_line_arrays_equal_the_vtk_film_fields_bit_for_bit() {
    let model = Model::from_json(include_str!("../../../examples/hinged_panel.json")).unwrap();
    let lines = reaction_lines(&model).0;
    assert_eq!(lines.len(), 2, "the rail and the frame");
    let source = Source::Model(model.clone());
    let arrays = Arrays::of(&describe(&source).unwrap());
    let u = Unpacked::new("lines", source);
    let out = u.dir.parent().unwrap().join("vtk");
    std::fs::create_dir_all(&out).unwrap();
    let log = Log::default();
    let fmu = Fmu3::initialized_with(
        &u,
        &log,
        (&[], &[]),
        &[
            ("results.directory", out.to_str().unwrap()),
            ("results.vtkFormat", "ascii"),
        ],
    );
    for k in 1..=2 {
        assert_eq!(fmu.set("rail.dz", -0.005 * k as f64), 0);
        assert_eq!(fmu.set("rail.angle", 0.01 * k as f64), 0);
        assert!(fmu.step(k as f64 - 1.0, 1.0) <= 1, "{:?}", log.take());
    }
    let file = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("_film_0002.vtu"))
        .expect("the film file of step 2");
    let xml = std::fs::read_to_string(file).unwrap();
    let field = data_array(&xml, "Name=\"line_reaction\"");
    let points = data_array(&xml, "<Points>");
    let vr = |f: Field| arrays.fields().find(|x| x.1 == f).unwrap().0;
    let read = |f: Field, n: usize| {
        let mut v = vec![f64::NAN; n];
        let r = vr(f);
        let status = unsafe { get_float64(fmu.c, &r, 1, v.as_mut_ptr(), n) };
        assert_eq!(status, 0, "{f:?}: {:?}", log.take());
        v
    };
    let mut summed = vec![0.0; field.len()];
    for (k, line) in lines.iter().enumerate() {
        let mut n = 0u64;
        let r = vr(Field::RailPoints(k));
        assert_eq!(unsafe { get_uint64(fmu.c, &r, 1, &mut n, 1) }, 0);
        assert_eq!(n as usize, line.nodes.len(), "{}", line.name);
        let q = read(Field::RailReaction(k), 3 * line.nodes.len());
        let x = read(Field::RailPosition(k), 3 * line.nodes.len());
        for (j, &v) in line.nodes.iter().enumerate() {
            for c in 0..3 {
                summed[3 * v + c] += q[3 * j + c];
                assert_eq!(x[3 * j + c].to_bits(), points[3 * v + c].to_bits());
                // A node of this line alone: its value is the field's.
                if lines.iter().filter(|l| l.nodes.contains(&v)).count() == 1 {
                    assert_eq!(q[3 * j + c], field[3 * v + c]);
                }
            }
        }
        assert!(q.iter().any(|&q| q != 0.0), "{}", line.name);
        if let Some(arc) = &line.position {
            assert_eq!(&read(Field::RailArc(k), arc.len()), arc);
        }
    }
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&summed), bits(&field));
    assert!(lines.iter().any(|l| l.position.is_some()));
}
