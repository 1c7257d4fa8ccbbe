//! Pattern files and garments: malformed patterns named by file, line and column, the
//! shipped patterns, seams joining matching nodes, broken garments refused, named runs.

use super::*;

fn parse_err(text: &[u8]) -> (usize, usize, PatternErrorKind) {
    let e = Pattern::parse(text, "bad.txt").expect_err("must be refused");
    assert_eq!(e.file, "bad.txt");
    assert!(
        e.to_string()
            .starts_with(&format!("bad.txt:{}:{}: ", e.line, e.column))
    );
    (e.line, e.column, e.kind)
}

#[test]
fn malformed_patterns_name_file_line_and_column() {
    // Empty: no rows at all, only comments, or no 1.
    assert_eq!(parse_err(b"").2, PatternErrorKind::Empty);
    assert_eq!(parse_err(b"# nothing\n\n").2, PatternErrorKind::Empty);
    assert_eq!(
        parse_err(b"# c\n000\n000\n"),
        (2, 1, PatternErrorKind::Empty)
    );
    // Ragged: a short row, and a long row (reported at its first extra node).
    assert_eq!(
        parse_err(b"111\n11\n"),
        (
            2,
            3,
            PatternErrorKind::Ragged {
                expected: 3,
                found: 2
            }
        )
    );
    assert_eq!(
        parse_err(b"111\n# ok\n1 1 1 1\n"),
        (
            3,
            7,
            PatternErrorKind::Ragged {
                expected: 3,
                found: 4
            }
        )
    );
    // A stray character, even in the middle of a row.
    assert_eq!(
        parse_err(b"111\n1x1\n"),
        (2, 2, PatternErrorKind::BadCharacter('x'))
    );
    assert_eq!(
        parse_err("11\n1й\n".as_bytes()),
        (2, 2, PatternErrorKind::BadCharacter('й'))
    );
    // Not UTF-8: the position of the first bad byte.
    assert_eq!(
        parse_err(b"11\n1\xff1\n"),
        (2, 2, PatternErrorKind::NotUtf8)
    );
    // Too large: one line longer than the limit, and many lines.
    let long = vec![b'1'; MAX_PATTERN_NODES + 1];
    assert!(matches!(
        parse_err(&long).2,
        PatternErrorKind::TooLarge { .. }
    ));
    let tall = "1111111111\n".repeat(MAX_PATTERN_NODES / 10 + 1);
    let (line, _, kind) = parse_err(tall.as_bytes());
    assert!(matches!(kind, PatternErrorKind::TooLarge { .. }));
    assert_eq!(line, MAX_PATTERN_NODES / 10 + 1);
    // A missing file.
    let e = Pattern::load(Path::new("no/such/pattern.txt")).unwrap_err();
    assert!(matches!(e.kind, PatternErrorKind::Io(_)), "{e}");
}

#[test]
fn comments_blank_lines_and_spaces_are_allowed_and_islands_warn() {
    let (p, warnings) =
        Pattern::parse(b"# piece\n\n1 1 0 0 # two\r\n1100\n0000\n0001\n", "p.txt").unwrap();
    assert_eq!((p.width, p.height, p.count()), (4, 4, 5));
    assert!(p.has(0, 0) && p.has(1, 1) && !p.has(2, 0) && p.has(3, 3));
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert_eq!((warnings[0].line, warnings[0].column), (6, 4));
    assert!(warnings[0].to_string().starts_with("p.txt:6:4: 1 node(s)"));
    // Diagonal neighbours are joined by shear springs: one island.
    let (_, warnings) = Pattern::parse(b"10\n01\n", "d.txt").unwrap();
    assert!(warnings.is_empty());
}

#[test]
fn rescaling_keeps_the_outline_on_a_finer_grid() {
    let (p, _) = Pattern::parse(b"110\n111\n", "l.txt").unwrap();
    let fine = p.rescale(2);
    assert_eq!((fine.width, fine.height), (5, 3));
    // Every coarse node stays; the cell with a missing corner stays empty inside, but the
    // present edges of it stay.
    for (c, r) in [(0, 0), (1, 0), (0, 1), (1, 1), (2, 1)] {
        assert!(fine.has(2 * c, 2 * r), "({c}, {r})");
    }
    // The cell with three nodes keeps its triangle: the node on its diagonal stays.
    assert!(!fine.has(4, 0) && !fine.has(3, 0) && fine.has(3, 1));
    assert!(fine.has(1, 0) && fine.has(1, 1) && fine.has(3, 2) && fine.has(2, 1));
    assert_eq!(fine.count(), 12);
    // A diagonal outline: the triangle's inside at resolution 4.
    let (tri, _) = Pattern::parse(b"10\n11\n", "t.txt").unwrap();
    let fine = tri.rescale(4);
    assert_eq!(
        fine.count(),
        15,
        "1 + 2 + 3 + 4 + 5 nodes on and under the diagonal"
    );
    assert!(fine.has(2, 2) && !fine.has(3, 2) && fine.has(0, 4) && fine.has(4, 4));
}

fn tshirt(resolution: u32) -> GarmentLayout {
    GarmentLayout::load(&asset_path("patterns/tshirt.ron"), resolution).expect("tshirt loads")
}

#[test]
fn the_shipped_patterns_parse_to_their_node_counts() {
    for side in ["front", "back"] {
        let (p, warnings) =
            Pattern::load(&asset_path(&format!("patterns/tshirt_{side}.txt"))).unwrap();
        assert_eq!((p.width, p.height, p.count()), (30, 23, 510), "{side}");
        assert!(warnings.is_empty());
    }
    let coarse = tshirt(1);
    assert_eq!(coarse.positions.len(), 1020, "about the seed's 1,008");
    let fine = tshirt(2);
    assert!(fine.positions.len() > 3 * 1020, "{}", fine.positions.len());
    // Same outline: the same extent in space.
    let extent = |l: &GarmentLayout| {
        l.positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    };
    let (a, b) = (extent(&coarse), extent(&fine));
    assert!(
        a.0.distance(b.0) < 1e-5 && a.1.distance(b.1) < 1e-5,
        "{a:?} {b:?}"
    );
}

/// Which piece a particle belongs to.
fn piece_of(layout: &GarmentLayout, i: u32) -> &str {
    &layout
        .pieces
        .iter()
        .find(|(_, r)| r.contains(&i))
        .unwrap()
        .0
}

#[test]
fn seams_join_front_to_matching_back_nodes_symmetrically_and_leave_openings() {
    for resolution in [1, 2] {
        let layout = tshirt(resolution);
        let x = &layout.positions;
        let spacing = 0.034 / resolution as f32;
        let seam_springs: Vec<[u32; 2]> =
            layout.seams.iter().flat_map(|(_, s)| s.clone()).collect();
        assert_eq!(
            layout
                .springs
                .iter()
                .filter(|s| s.0 == SpringKind::Seam)
                .count(),
            seam_springs.len()
        );
        for &[a, b] in &seam_springs {
            assert_eq!(
                (piece_of(&layout, a), piece_of(&layout, b)),
                ("front", "back")
            );
            // The matching node: the same place on the body, across the gap.
            let (pa, pb) = (x[a as usize], x[b as usize]);
            assert!(
                (pa.x - pb.x).abs() < 1e-5 && (pa.y - pb.y).abs() < 1e-5,
                "{pa} vs {pb}"
            );
            assert!((pa.z - pb.z - 0.34).abs() < 1e-6);
        }
        // Counts per seam at resolution 1: shoulders 12, under sleeves 6, sides 15.
        let count = |name: &str| {
            layout
                .seams
                .iter()
                .find(|(n, _)| n == name)
                .unwrap()
                .1
                .len()
        };
        let f = resolution as usize;
        for (side, other) in [("right", "left")] {
            for (seam, n) in [("shoulder", 12), ("under sleeve", 6), ("side", 15)] {
                let (a, b) = (
                    count(&format!("{side} {seam}")),
                    count(&format!("{other} {seam}")),
                );
                assert_eq!((a, b), ((n - 1) * f + 1, (n - 1) * f + 1), "{seam}");
            }
        }
        // Left/right symmetry: every seam node has a mirror image across x = 0.
        for &[a, _] in &seam_springs {
            let mirror = x[a as usize] * Vec3::new(-1.0, 1.0, 1.0);
            assert!(
                seam_springs
                    .iter()
                    .any(|&[m, _]| x[m as usize].distance(mirror) < 1e-5),
                "no mirror of {}",
                x[a as usize]
            );
        }
        // Openings: the neck edge (rows 0–2 next to the hole), the hem between the side
        // seams and the sleeve ends between the shoulder and the under-sleeve seam have no
        // seam spring.
        let seamed = |i: usize| seam_springs.iter().any(|s| s.contains(&(i as u32)));
        let front = layout.pieces[0].1.clone();
        let top = x[front.start as usize].y;
        let row = |i: usize| ((top - x[i].y) / spacing).round() as i32;
        let half_torso = 8.5 * 0.034;
        let half_width = 14.5 * 0.034;
        let mut checked = [0; 3];
        let front_particles = x.iter().enumerate().take(front.end as usize);
        for (i, p) in front_particles.skip(front.start as usize) {
            let (px, r) = (p.x, row(i));
            let neck = r > 0 && r <= 3 * resolution as i32 && px.abs() < 0.15;
            let hem = r == 22 * resolution as i32 && px.abs() < half_torso - 1e-4;
            let sleeve_end =
                (px.abs() - half_width).abs() < 1e-4 && r > 0 && r < 8 * resolution as i32;
            for (k, opening) in [neck, hem, sleeve_end].into_iter().enumerate() {
                if opening {
                    assert!(
                        !seamed(i),
                        "particle {i} at {p} is in an opening but seamed"
                    );
                    checked[k] += 1;
                }
            }
        }
        assert!(checked.iter().all(|&c| c > 0), "{checked:?}");
    }
}

#[test]
fn broken_garments_name_the_file_and_what_is_wrong() {
    let patterns = |name: &str| match name {
        "a.txt" => Pattern::parse(b"111\n111\n", "a.txt"),
        "bad.txt" => Pattern::parse(b"111\n1x1\n", "bad.txt"),
        "hole.txt" => Pattern::parse(b"101\n111\n", "hole.txt"),
        _ => Err(Pattern::parse(b"", name).unwrap_err()),
    };
    let garment = |seams: &str, pattern: &str| {
        let text = format!(
            "(spacing: 0.1, pieces: [(name: \"a\", pattern: \"a.txt\"), (name: \"b\", pattern: \"{pattern}\", translation: (0, 0, 1))],\n seams: [{seams}])"
        );
        GarmentLayout::parse(&text, "g.ron", 1, patterns).map(|l| l.seams.len())
    };
    let ok = "(name: \"s\", a: (piece: \"a\", from: (0, 0), to: (2, 0)), b: (piece: \"b\", from: (0, 0), to: (2, 0)))";
    assert_eq!(garment(ok, "a.txt"), Ok(1));
    let message = |r: Result<usize, ClothError>| r.unwrap_err().to_string();
    // The pattern's own error comes through with its file, line and column.
    assert_eq!(
        message(garment(ok, "bad.txt")),
        "bad.txt:2:2: unexpected character 'x': a pattern row holds only 0 and 1 (spaces and `#` comments allowed)"
    );
    let m = message(garment(&ok.replace("(2, 0)))", "(1, 0)))"), "a.txt"));
    assert!(
        m.starts_with("g.ron:2:") && m.contains("edge a has 3 nodes but edge b has 2"),
        "{m}"
    );
    let m = message(garment(
        &ok.replace("to: (2, 0)), b", "to: (2, 5)), b"),
        "a.txt",
    ));
    assert!(
        m.contains("not along a row, a column or a 45° diagonal"),
        "{m}"
    );
    let m = message(garment(
        &ok.replace("(0, 0), to: (2, 0)), b", "(0, 1), to: (2, 3)), b"),
        "a.txt",
    ));
    assert!(
        m.contains("`to` (2, 3) is outside piece `a` (3×2 nodes"),
        "{m}"
    );
    // A run far outside its piece is refused before its nodes are listed.
    let m = message(garment(
        &ok.replace("to: (2, 0)), b", "to: (4294967295, 0)), b"),
        "a.txt",
    ));
    assert!(
        m.contains("`to` (4294967295, 0) is outside piece `a`"),
        "{m}"
    );
    // Inside the piece but on a 0 of its pattern.
    assert!(message(garment(ok, "hole.txt")).contains("node (1, 0) of `b` is not in the pattern"));
    let m = message(garment(
        &ok.replace("piece: \"b\"", "piece: \"c\""),
        "a.txt",
    ));
    assert!(m.contains("no piece is named `c`"), "{m}");
    let m = message(
        GarmentLayout::parse("(spacing: 0.1, pieces: [], extra: 1)", "g.ron", 1, patterns)
            .map(|_| 0),
    );
    assert!(m.starts_with("g.ron:1:"), "{m}");
}

#[test]
fn named_runs_list_their_particles_and_bad_ones_are_refused() {
    // The T-shirt's runs: the front's shoulders, row 0, columns 6–11 and 18–23 — the
    // particles at those nodes, in order (the front piece is first; its row 0 holds
    // columns 0–11 and 18–29, so column c is particle c, or c − 6 past the neck).
    for resolution in [1, 2] {
        let layout = tshirt(resolution);
        let f = resolution;
        let run = |name: &str| {
            layout
                .runs
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("{name}"))
                .1
                .clone()
        };
        let (right, left) = (run("right shoulder"), run("left shoulder"));
        assert_eq!(right.len() as u32, 5 * f + 1);
        assert_eq!(left.len() as u32, 5 * f + 1);
        // Along the top row of the front piece: all at its top (y = 0), spacing apart.
        let spacing = 0.034 / f as f32;
        for particles in [&right, &left] {
            for pair in particles.windows(2) {
                let (a, b) = (
                    layout.positions[pair[0] as usize],
                    layout.positions[pair[1] as usize],
                );
                assert!(a.y.abs() < 1e-6 && b.y.abs() < 1e-6);
                assert!((b.x - a.x - spacing).abs() < 1e-6, "{a} → {b}");
                assert!((a.z - 0.17).abs() < 1e-6, "on the front piece: {a}");
            }
        }
        assert_eq!(right[0], 6 * f, "front row 0, column 6");
        // The solver keeps them by name.
        let solver = ClothSolver::new(
            layout.clone().into_layout(),
            &[],
            &ClothParams::seeds(),
            Affine3A::IDENTITY,
        )
        .unwrap();
        assert_eq!(solver.run("left shoulder"), Some(left.as_slice()));
        assert_eq!(solver.run("collar"), None);
    }
    // Refused, with the file and the line of the run.
    let patterns = |name: &str| match name {
        "a.txt" => Pattern::parse(b"111\n101\n", "a.txt"),
        _ => Err(Pattern::parse(b"", name).unwrap_err()),
    };
    let garment = |runs: &str| {
        let text = format!(
            "(spacing: 0.1, pieces: [(name: \"a\", pattern: \"a.txt\")],\n runs: [{runs}])"
        );
        GarmentLayout::parse(&text, "g.ron", 1, patterns).map(|l| l.runs)
    };
    assert_eq!(
        garment("(name: \"top\", nodes: (piece: \"a\", from: (0, 0), to: (2, 0)))"),
        Ok(vec![("top".to_string(), vec![0, 1, 2])])
    );
    for (runs, expected) in [
        (
            "(name: \"r\", nodes: (piece: \"b\", from: (0, 0), to: (2, 0)))",
            "g.ron:2:16: run `r`: no piece is named `b`",
        ),
        (
            "(name: \"r\", nodes: (piece: \"a\", from: (0, 0), to: (3, 0)))",
            "g.ron:2:16: run `r`: `to` (3, 0) is outside piece `a` (3×2 nodes at resolution 1)",
        ),
        (
            "(name: \"r\", nodes: (piece: \"a\", from: (0, 1), to: (2, 1)))",
            "g.ron:2:16: run `r`: node (1, 1) of `a` is not in the pattern",
        ),
        (
            "(name: \"r\", nodes: (piece: \"a\", from: (0, 0), to: (0, 1))), (name: \"r\", nodes: (piece: \"a\", from: (2, 0), to: (2, 1)))",
            "g.ron:2:16: two runs are named `r`",
        ),
    ] {
        assert_eq!(garment(runs).unwrap_err().to_string(), expected, "{runs}");
    }
}
