//! Bodies made from files: the cells of a Gmsh mesh, filled by their quadrature points, and the
//! inside of a closed STL surface (`tests/meshes/`, made by Gmsh from the `.geo` files beside them).
//! The points' volumes sum to the mesh's to round-off in the plane, in axial symmetry and in three
//! dimensions; the surface's to the point spacing; a mesh-filled body runs on one and two ranks
//! with the same answers; what is wrong with a file is named.

mod common;

use porompm::case::Case;
use porompm::geometry::CellKind;
use porompm::model::particles::Particles;
use std::f64::consts::PI;

/// A one-phase elastic case on a grid of `size` and `cells` whose bodies are `bodies` (TOML).
fn case(size: &str, cells: &str, bodies: &str, extra: &str) -> Result<Case, String> {
    let text = format!(
        r#"
        [analysis]
        formulation = "one_phase"
        {extra}
        [grid]
        size = {size}
        cells = {cells}
        [[materials]]
        name = "soil"
        porosity = 0.3
        solid_density = 2000.0
        [materials.model]
        type = "linear_elastic"
        young_modulus = 1e7
        poisson_ratio = 0.3
        {bodies}
        [[stages]]
        name = "load"
        duration = 0.1
        dt = 0.1
        "#
    );
    porompm::validation::load(&text, "tests/t.toml", &[]).map_err(|e| e.to_string())
}

fn body(name: &str, shape: &str) -> String {
    format!("[[bodies]]\nname = \"{name}\"\nmaterial = \"soil\"\nshape = {shape}\n")
}

/// Σ of the points' volumes of each body.
fn volumes<const D: usize>(c: &Case) -> Vec<f64> {
    let ps = Particles::<D>::generate(c, &porompm::model::grid_of::<D>(c), |_| true);
    (0..c.bodies.len())
        .map(|b| (0..ps.len()).filter(|&k| ps.body[k] as usize == b).map(|k| ps.volume[k]).sum())
        .collect()
}

/// The area and the first moment ∫ x dA of a polygon (the shoelace formula and its moment).
fn polygon(v: &[[f64; 2]]) -> (f64, f64) {
    let (mut a, mut m) = (0.0, 0.0);
    for i in 0..v.len() {
        let (p, q) = (v[i], v[(i + 1) % v.len()]);
        let c = p[0] * q[1] - q[0] * p[1];
        a += 0.5 * c;
        m += c * (p[0] + q[0]) / 6.0;
    }
    (a, m)
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// The plane slope on its rock layer (quadrangles under triangles, two physical groups): each
/// body's points sum to its polygon's area to 1e-12, in plane strain with one and with three or
/// four points a cell, and in axial symmetry to 2π ∫ r dA (Pappus) with the rule of order 2.
#[test]
fn a_gmsh_body_has_the_mesh_s_volume_in_the_plane_and_in_axial_symmetry() {
    let rock = [[0.0, 0.0], [4.0, 0.0], [4.0, 0.5], [0.0, 0.5]];
    let soil = [[0.0, 0.5], [4.0, 0.5], [4.0, 1.0], [2.6, 1.0], [1.4, 1.9], [0.0, 1.9]];
    let (areas, moments) = ([polygon(&rock).0, polygon(&soil).0], [polygon(&rock).1, polygon(&soil).1]);
    for order in [1, 2] {
        let bodies = body(
            "rock",
            &format!("{{ mesh = {{ file = \"meshes/layers_2d.msh\", group = \"rock\", order = {order} }} }}"),
        ) + &body(
            "soil",
            &format!("{{ mesh = {{ file = \"meshes/layers_2d.msh\", group = 2, order = {order} }} }}"),
        );
        let c = case("[4.0, 2.0]", "[16, 8]", &bodies, "").unwrap();
        let v = volumes::<2>(&c);
        for b in 0..2 {
            println!("plane, order {order}, body {b}: volume error {:.1e}", relative(v[b], areas[b]));
            assert!(relative(v[b], areas[b]) < 1e-12, "order {order}, body {b}: {} against {}", v[b], areas[b]);
        }
    }
    let bodies = body("rock", "{ mesh = { file = \"meshes/layers_2d.msh\", group = \"rock\" } }")
        + &body("soil", "{ mesh = { file = \"meshes/layers_2d.msh\", group = \"soil\" } }");
    let c = case("[4.0, 2.0]", "[16, 8]", &bodies, "geometry = \"axisymmetric\"").unwrap();
    let v = volumes::<2>(&c);
    for b in 0..2 {
        let ring = 2.0 * PI * moments[b];
        println!("axial symmetry, body {b}: volume error {:.1e}", relative(v[b], ring));
        assert!(relative(v[b], ring) < 1e-12, "body {b}: {} against {ring}", v[b]);
    }
}

/// The embankment (hexahedra) on its foundation (prisms) and the ball (tetrahedra): each body's
/// points sum to its volume to 1e-12, the ball's to the volume its skin's triangles enclose (the
/// divergence theorem, independent of the cells' quadrature).
#[test]
fn a_gmsh_body_has_the_mesh_s_volume_in_three_dimensions() {
    for order in [1, 2] {
        let bodies = body(
            "foundation",
            &format!("{{ mesh = {{ file = \"meshes/embankment.msh\", group = \"foundation\", order = {order} }} }}"),
        ) + &body(
            "fill",
            &format!("{{ mesh = {{ file = \"meshes/embankment.msh\", group = \"fill\", order = {order} }} }}"),
        );
        let c = case("[6.0, 2.0, 2.0]", "[12, 4, 4]", &bodies, "").unwrap();
        let v = volumes::<3>(&c);
        println!("3D, order {order}: volume errors {:.1e}, {:.1e}", relative(v[0], 12.0), relative(v[1], 5.0));
        assert!(relative(v[0], 12.0) < 1e-12 && relative(v[1], 5.0) < 1e-12, "order {order}: {v:?}");
    }
    let file = porompm::io::geometry::read_msh(std::path::Path::new("tests/meshes/ball.msh")).unwrap();
    let skin = file.names.iter().find(|n| n.2 == "skin").unwrap().1;
    let enclosed: f64 = (file.cells.iter())
        .filter(|c| c.kind == CellKind::Triangle && c.groups.contains(&skin))
        .map(|c| {
            let [a, b, d] = [0, 1, 2].map(|k| file.nodes[c.nodes[k]]);
            a[0] * (b[1] * d[2] - b[2] * d[1]) - a[1] * (b[0] * d[2] - b[2] * d[0]) + a[2] * (b[0] * d[1] - b[1] * d[0])
        })
        .sum::<f64>()
        .abs()
        / 6.0;
    let c = case("[1.0, 1.0, 1.0]", "[10, 10, 10]", &body("ball", "{ mesh = { file = \"meshes/ball.msh\" } }"), "")
        .unwrap();
    let v = volumes::<3>(&c)[0];
    println!("3D ball: volume error {:.1e}", relative(v, enclosed));
    assert!(relative(v, enclosed) < 1e-12, "{v} against {enclosed}");
    // Facets of about 0.06 m on a radius of 0.3 m cut 1.4 % off the sphere.
    assert!(relative(v, 4.0 / 3.0 * PI * 0.027) < 0.02, "the faceted ball is close to the sphere: {v}");
}

/// The ball's STL surface (Gmsh's triangles of the same sphere) at point spacings 0.05, 0.025
/// and 0.0125 m: the points' volumes approach the volume the surface encloses, within 1 % at the
/// finest; scaled from millimetres and moved, the same points.
#[test]
fn an_stl_body_has_the_enclosed_volume_to_the_point_spacing() {
    let errors: Vec<f64> = [10, 20, 40]
        .iter()
        .map(|n| {
            let shape = "{ surface = { file = \"meshes/ball.stl\" } }";
            let c = case("[1.0, 1.0, 1.0]", &format!("[{n}, {n}, {n}]"), &body("ball", shape), "").unwrap();
            let porompm::case::Shape::Surface(s) = &c.bodies[0].shape else { unreachable!() };
            let enclosed = s.surface().volume();
            relative(volumes::<3>(&c)[0], enclosed)
        })
        .collect();
    println!("STL ball: volume errors at spacings 0.05, 0.025, 0.0125 m: {errors:?}");
    assert!(errors[2] < 0.01 && errors[2] < errors[0], "{errors:?}");
    // Twice as large: the same points, scaled, eight times the volume; moved, the bounds move.
    let ball = |t: &str| body("ball", &format!("{{ surface = {{ file = \"meshes/ball.stl\"{t} }} }}"));
    let unit = case("[1.0, 1.0, 1.0]", "[10, 10, 10]", &ball(""), "").unwrap();
    let twice = case("[2.0, 2.0, 2.0]", "[10, 10, 10]", &ball(", scale = 2.0"), "").unwrap();
    let (v1, v2) = (volumes::<3>(&unit)[0], volumes::<3>(&twice)[0]);
    assert!(relative(v2, 8.0 * v1) < 1e-12, "{v2} against 8 × {v1}");
    let moved = case("[2.0, 1.0, 1.0]", "[20, 10, 10]", &ball(", offset = [1.0, 0.0, 0.0]"), "").unwrap();
    assert_eq!(moved.bodies[0].shape.bounds().0[0], unit.bodies[0].shape.bounds().0[0] + 1.0);
}

/// The elastic embankment on its foundation, both filled from the Gmsh mesh
/// (`tests/cases/embankment_mesh_3d.toml`), under its weight on one and two ranks: the grid's
/// vertical reactions carry ρ g V with V = 17 m³, the mesh's volume, to 1e-9, and two ranks give
/// the one-rank history to round-off.
#[test]
fn a_mesh_filled_embankment_carries_its_weight_on_one_and_two_ranks() {
    let weight = 2000.0 * 9.81 * 17.0;
    let mut histories = Vec::new();
    for ranks in [1, 2] {
        let dir = std::env::temp_dir().join(format!("porompm-embankment-mesh-{ranks}"));
        let r = common::run_case_on(ranks, "tests/cases/embankment_mesh_3d.toml", &dir, &[]);
        assert!(r.completed(), "{ranks} ranks: {}", r.stderr());
        let carried: f64 = (r.header.iter().enumerate())
            .filter(|(_, h)| h.ends_with(".reaction_y"))
            .map(|(c, _)| r.rows.last().expect("a row")[c])
            .sum();
        assert!(
            relative(carried, weight) < 1e-9,
            "{ranks} ranks: the reactions carry {carried}, the weight is {weight}"
        );
        assert_eq!(r.summary["particles"], 1200 + 256);
        histories.push((r.header, r.rows));
    }
    let ((header, one), (_, two)) = (&histories[0], &histories[1]);
    let skip = header.iter().position(|h| h == "load_imbalance");
    assert_eq!(one.len(), two.len());
    for (a, b) in one.iter().zip(two) {
        for (_, (x, y)) in a.iter().zip(b).enumerate().filter(|(c, _)| Some(*c) != skip) {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{x} on one rank, {y} on two");
        }
    }
}

/// What is wrong with a body's file is named with its key: a missing file, a file that is not a
/// mesh, a group the mesh does not have (listing those it has), a mesh without cells of the case's
/// dimension, a surface with a hole, an STL surface or a perturbation where they do not apply, and
/// a mesh body that overlaps another body.
#[test]
fn a_body_s_file_and_what_is_wrong_with_it_are_named() {
    let plane = |shape: &str| case("[4.0, 2.0]", "[16, 8]", &body("b", shape), "").unwrap_err();
    let cases = [
        (plane("{ mesh = { file = \"meshes/none.msh\" } }"), "key `bodies[0].shape.mesh.file`: cannot read tests/meshes/none.msh"),
        (plane("{ mesh = { file = \"meshes/ball.geo\" } }"), "tests/meshes/ball.geo is not a Gmsh mesh: it does not start with $MeshFormat"),
        (
            plane("{ mesh = { file = \"meshes/layers_2d.msh\", group = \"clay\" } }"),
            "key `bodies[0].shape.mesh`: tests/meshes/layers_2d.msh: it has no physical group of dimension 2 named \"clay\"; it has \"rock\" (1), \"soil\" (2)",
        ),
        (plane("{ mesh = { file = \"meshes/embankment.msh\" } }"), "its cell 0 of dimension 2 lies off the plane z = 0"),
        (plane("{ mesh = { file = \"meshes/embankment.msh\", group = \"fill\" } }"), "no physical group of dimension 2 named \"fill\"; it has \"bottom\" (3)"),
        (plane("{ mesh = { file = \"meshes/layers_2d.msh\", order = 3 } }"), "key `bodies[0].shape.mesh.order`: 1 or 2, got 3"),
        (plane("{ surface = { file = \"meshes/ball.stl\" } }"), "a box, sphere, cylinder or surface is a shape of a three-dimensional case"),
        (
            case("[4.0, 2.0]", "[16, 8]", &(body("b", "{ mesh = { file = \"meshes/layers_2d.msh\" } }") + "perturbation = 0.1\n"), "")
                .unwrap_err(),
            "key `bodies[0].perturbation`: moves the points of a body filled on the grid",
        ),
        (
            case(
                "[4.0, 2.0]",
                "[16, 8]",
                &(body("b", "{ mesh = { file = \"meshes/layers_2d.msh\", group = \"rock\" } }")
                    + &body("c", "{ rectangle = { min = [0.0, 0.0], max = [1.0, 1.0] } }")),
                "",
            )
            .unwrap_err(),
            "body `c` overlaps body `b` (bodies[0])",
        ),
    ];
    for (e, want) in cases {
        assert!(e.contains(want), "{e}\nshould say: {want}");
    }
    // A surface pressure needs material on one side of its surface: the ball's skin presses the
    // ball; the skin moved into the empty half of the grid has none, shrunk into the ball material
    // on both sides; in the plane it is refused.
    let pressed = |stl: &str| {
        let load = format!(
            "[[loads]]\nname = \"p\"\nkind = \"surface_pressure\"\npressure = 1.0\nsurface = {{ stl = {{ file = \"meshes/ball.stl\"{stl} }} }}\n"
        );
        case(
            "[2.0, 1.0, 1.0]",
            "[20, 10, 10]",
            &(body("ball", "{ mesh = { file = \"meshes/ball.msh\" } }") + &load),
            "",
        )
    };
    assert!(pressed("").is_ok(), "{:?}", pressed("").err());
    let e = pressed(", offset = [1.0, 0.0, 0.0]").unwrap_err();
    assert!(
        e.contains("key `loads[0].surface`: meshes/ball.stl: its surface at") && e.contains("material on neither side"),
        "{e}"
    );
    let e = pressed(", scale = 0.5, offset = [0.25, 0.25, 0.25]").unwrap_err();
    assert!(e.contains("material on both sides"), "{e}");
    let e = case(
        "[4.0, 2.0]",
        "[16, 8]",
        &(body("b", "{ mesh = { file = \"meshes/layers_2d.msh\" } }")
            + "[[loads]]\nname = \"p\"\nkind = \"surface_pressure\"\npressure = 1.0\nsurface = { mesh = { file = \"meshes/layers_2d.msh\" } }\n"),
        "",
    )
    .unwrap_err();
    assert!(e.contains("a surface pressure acts in a three-dimensional case"), "{e}");
    // An STL surface with one triangle taken out; a mesh of Gmsh's format 2.2; a broken one.
    let dir = std::env::temp_dir().join("porompm-open-stl");
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = |name: &str, text: &str| {
        std::fs::write(dir.join(name), text).unwrap();
        plane(&format!("{{ mesh = {{ file = \"{}\" }} }}", dir.join(name).display()))
    };
    let e = mesh("old.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    assert!(
        e.contains("is a Gmsh mesh of format 2.2; porompm reads format 4.1 (save it with `gmsh -format msh41`"),
        "{e}"
    );
    let e = mesh("broken.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nbroken\n$EndNodes\n");
    assert!(e.contains("broken.msh is not a readable Gmsh MSH 4.1 file: ") && !e.contains("Hex dump"), "{e}");
    let text = std::fs::read_to_string("tests/meshes/ball.stl").unwrap();
    let start = text.find("facet").unwrap();
    let end = start + text[start..].find("endfacet").unwrap() + "endfacet".len();
    std::fs::write(dir.join("open.stl"), format!("{}{}", &text[..start], &text[end..])).unwrap();
    let shape = format!("{{ surface = {{ file = \"{}\" }} }}", dir.join("open.stl").display());
    let e = case("[1.0, 1.0, 1.0]", "[10, 10, 10]", &body("b", &shape), "").unwrap_err();
    assert!(e.contains("it is not closed: 3 of its"), "{e}");
}

/// A particle file written from the points a rectangle is filled with (plane strain and axial
/// symmetry, where a row's volume is its ring's) gives those points back: positions, volumes and
/// GIMP domains to round-off; another body over them is refused; what is wrong with a file is named.
#[test]
fn a_particle_file_gives_its_points() {
    let dir = std::env::temp_dir().join("porompm-particle-files");
    std::fs::create_dir_all(&dir).unwrap();
    for geometry in ["", "geometry = \"axisymmetric\""] {
        let block = body("block", "{ rectangle = { min = [0.2, 0.1], max = [0.8, 0.7] } }");
        let c = case("[1.0, 1.0]", "[10, 10]", &block, geometry).unwrap();
        let ps = Particles::<2>::generate(&c, &porompm::model::grid_of::<2>(&c), |_| true);
        let mut text = String::from("# written by the test\nid,x,y,volume\n");
        for k in 0..ps.len() {
            text += &format!("{k},{:e},{:e},{:e}\n", ps.x[k][0], ps.x[k][1], ps.volume[k]);
        }
        let file = dir.join(format!("block{}.csv", geometry.len()));
        std::fs::write(&file, text).unwrap();
        let shape = format!("{{ points = {{ file = \"{}\" }} }}", file.display());
        let from_file = case("[1.0, 1.0]", "[10, 10]", &body("block", &shape), geometry).unwrap();
        let qs = Particles::<2>::generate(&from_file, &porompm::model::grid_of::<2>(&from_file), |_| true);
        assert_eq!(qs.len(), ps.len());
        for k in 0..ps.len() {
            assert_eq!(qs.x[k], ps.x[k]);
            assert!(
                relative(qs.volume[k], ps.volume[k]) < 1e-14,
                "{geometry}: {} against {}",
                qs.volume[k],
                ps.volume[k]
            );
            assert!(
                (0..2).all(|d| relative(qs.lp[k][d], ps.lp[k][d]) < 1e-14),
                "{:?} against {:?}",
                qs.lp[k],
                ps.lp[k]
            );
        }
        let over = body("block", &shape) + &body("cap", "{ rectangle = { min = [0.0, 0.6], max = [1.0, 1.0] } }");
        let e = case("[1.0, 1.0]", "[10, 10]", &over, geometry).unwrap_err();
        assert!(e.contains("body `cap` overlaps body `block`"), "{e}");
    }
    hdf5_particle_file(&dir);
    let bad = |name: &str, text: &str, geometry: &str| {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        let shape = format!("{{ points = {{ file = \"{}\" }} }}", file.display());
        case("[1.0, 1.0]", "[10, 10]", &body("b", &shape), geometry).unwrap_err()
    };
    let e = bad("no_volume.csv", "x,y\n0.5,0.5\n", "");
    assert!(e.contains("its header has no column `volume` (it needs x, y, volume)"), "{e}");
    let e = bad("word.csv", "x,y,volume\n0.5,0.5,1e-3\n0.5,half,1e-3\n", "");
    assert!(e.contains("line 3: `half` in column `y` is not a number"), "{e}");
    let e = bad("negative.csv", "x,y,volume\n0.5,0.5,-1e-3\n", "");
    assert!(e.contains("its point 0 has the measure -0.001, which must be positive"), "{e}");
    let e = bad("axis.csv", "x,y,volume\n0.0,0.5,1e-3\n", "geometry = \"axisymmetric\"");
    assert!(e.contains("its point 0 is at r = 0; a ring needs r > 0"), "{e}");
}

/// An HDF5 particle file (one-dimensional datasets in the root group named as a CSV's columns, here
/// the positions and volumes in double precision and the initial velocity in single) gives the
/// points the same numbers give from a CSV file; a dataset of another length and a missing one are
/// refused, naming them.
fn hdf5_particle_file(dir: &std::path::Path) {
    use hdf5_metno as h5;
    let block = body("block", "{ rectangle = { min = [0.2, 0.1], max = [0.8, 0.7] } }");
    let c = case("[1.0, 1.0]", "[10, 10]", &block, "").unwrap();
    let ps = Particles::<2>::generate(&c, &porompm::model::grid_of::<2>(&c), |_| true);
    let column = |f: fn(&Particles<2>, usize) -> f64| (0..ps.len()).map(|k| f(&ps, k)).collect::<Vec<f64>>();
    let (x, y, volume) = (column(|p, k| p.x[k][0]), column(|p, k| p.x[k][1]), column(|p, k| p.volume[k]));
    let vy: Vec<f32> = x.iter().map(|&x| (0.1 * x) as f32).collect();
    let write = |name: &str, with_volume: bool, short: bool| {
        let path = dir.join(name);
        let file = h5::File::create(&path).unwrap();
        let put = |name: &str, v: &[f64]| file.new_dataset_builder().with_data(v).create(name).unwrap();
        put("x", &x);
        put("y", if short { &y[1..] } else { &y });
        if with_volume {
            put("volume", &volume);
        }
        file.new_dataset_builder().with_data(&vy).create("vy").unwrap();
        file.new_dataset_builder().with_data(&vec![0.0f32; x.len()]).create("vx").unwrap();
        path
    };
    let read = |path: &std::path::Path| {
        let shape = format!("{{ points = {{ file = \"{}\" }} }}", path.display());
        case("[1.0, 1.0]", "[10, 10]", &body("block", &shape), "")
    };
    let from_file = read(&write("block.h5", true, false)).unwrap();
    let qs = Particles::<2>::generate(&from_file, &porompm::model::grid_of::<2>(&from_file), |_| true);
    assert_eq!(qs.len(), ps.len());
    for (k, v) in vy.iter().enumerate() {
        assert_eq!(qs.x[k], ps.x[k]);
        assert_eq!(qs.volume[k], ps.volume[k]);
        assert_eq!(qs.vel[k], [0.0, f64::from(*v)], "point {k}");
    }
    let e = read(&write("short.h5", true, true)).unwrap_err();
    assert!(e.contains("its datasets are of"), "{e}");
    let e = read(&write("no_volume.h5", false, false)).unwrap_err();
    assert!(e.contains("it has no dataset `volume` (it needs x, y, volume)"), "{e}");
}

/// A particle file's initial fields: each point starts with its row's velocity and stress; a field
/// the body gives too, a pore pressure in a one-phase case, a column of a group missing and a
/// value that is not finite are refused.
#[test]
fn a_particle_file_gives_its_points_their_initial_fields() {
    let dir = std::env::temp_dir().join("porompm-particle-fields");
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: &str| {
        let file = dir.join(name);
        std::fs::write(&file, text).unwrap();
        format!("{{ points = {{ file = \"{}\" }} }}", file.display())
    };
    let rows = "x,y,volume,vy,vx,sxx,syy,sxy,szz\n0.25,0.25,0.01,-1.0,2.0,-10.0,-20.0,3.0,-15.0\n0.75,0.25,0.01,-1.5,0.5,-11.0,-21.0,4.0,-16.0\n";
    let c = case("[1.0, 1.0]", "[10, 10]", &body("b", &write("fields.csv", rows)), "").unwrap();
    let ps = Particles::<2>::generate(&c, &porompm::model::grid_of::<2>(&c), |_| true);
    assert_eq!(ps.vel, vec![[2.0, -1.0], [0.5, -1.5]]);
    assert_eq!(ps.stress[1], [-11.0, -21.0, 4.0, -16.0, 0.0, 0.0]);
    let refused = [
        (
            body("b", &write("v.csv", "x,y,volume,vx,vy\n0.5,0.5,0.01,1,2\n"))
                + "initial = { velocity = [0.0, 1.0] }\n",
            "gives the points' velocity and the body gives it too",
        ),
        (
            body("b", &write("s.csv", "x,y,volume,sxx,syy,sxy,szz\n0.5,0.5,0.01,1,2,3,4\n"))
                + "uniform_stress = [0.0, 0.0, 0.0, 0.0]\n",
            "gives the points' stress and the body gives it too",
        ),
        (
            body("b", &write("p.csv", "x,y,volume,p\n0.5,0.5,0.01,1e3\n")),
            "a pore pressure, which a one_phase analysis has not",
        ),
        (
            body("b", &write("half.csv", "x,y,volume,vx\n0.5,0.5,0.01,1\n")),
            "its header has no column `vy` (it needs vx, vy)",
        ),
        (
            body("b", &write("nan.csv", "x,y,volume,vx,vy\n0.5,0.5,0.01,NaN,1\n")),
            "its point 0 has the velocity [NaN, 1.0, 0.0]",
        ),
    ];
    for (bodies, want) in refused {
        let e = case("[1.0, 1.0]", "[10, 10]", &bodies, "").unwrap_err();
        assert!(e.contains(want), "{e}\nshould say: {want}");
    }
}

/// A boundary from a mesh's physical group holds the grid nodes on its lines (plane) or faces
/// (3D): the slope's base line (y = 0, x from 0 to 4) the 17 nodes of the grid line under it; its
/// crest (a horizontal line at y = 1 from x = 2.6 to 4 and two lines off the grid's lines) the six
/// nodes of the horizontal part only; the embankment's base face (y = 0, 6 m × 2 m) the 13 × 5 nodes
/// on it. A group that misses the grid's lines is refused, naming them.
#[test]
fn a_boundary_from_a_mesh_group_holds_the_nodes_on_its_lines_and_faces() {
    use porompm::model::loads::mesh_nodes;
    let boundary = |group: &str, fix: &str| {
        format!("[[boundaries]]\nname = \"b\"\nmesh = {{ file = \"{group}\" }}\nfix = {fix}\n")
    };
    let slope = body("soil", "{ mesh = { file = \"meshes/layers_2d.msh\", group = \"soil\" } }");
    let nodes = |c: &Case| mesh_nodes(&porompm::model::grid_of::<2>(c), c.boundaries[0].mesh.as_ref().unwrap());
    let base = slope.clone() + &boundary("meshes/layers_2d.msh\", group = \"base", "[\"ux\", \"uy\"]");
    let c = case("[4.0, 2.0]", "[16, 8]", &base, "").unwrap();
    assert_eq!(nodes(&c), (0..17).map(|i| [i, 0]).collect::<Vec<_>>());
    let crest = slope.clone() + &boundary("meshes/layers_2d.msh\", group = \"crest", "[\"uy\"]");
    let c = case("[4.0, 2.0]", "[16, 8]", &crest, "").unwrap();
    assert_eq!(nodes(&c), (11..17).map(|i| [i, 4]).collect::<Vec<_>>());
    // A grid whose lines miss the crest's horizontal part (y = 1 lies between them).
    let e = case("[4.0, 2.1]", "[16, 6]", &crest, "").unwrap_err();
    assert!(e.contains("key `boundaries[0].mesh`: its lines hold no grid node"), "{e}");
    let e =
        case("[4.0, 2.0]", "[16, 8]", &(slope + &boundary("meshes/layers_2d.msh\", group = \"toe", "[\"uy\"]")), "")
            .unwrap_err();
    assert!(e.contains("no physical group of dimension 1 named \"toe\"") && e.contains("\"base\""), "{e}");
    let fill = body("fill", "{ mesh = { file = \"meshes/embankment.msh\", group = \"fill\" } }")
        + &boundary("meshes/embankment.msh\", group = \"bottom", "[\"ux\", \"uy\", \"uz\"]");
    let c = case("[7.0, 3.0, 2.0]", "[14, 6, 4]", &fill, "").unwrap();
    let on = mesh_nodes(&porompm::model::grid_of::<3>(&c), c.boundaries[0].mesh.as_ref().unwrap());
    assert_eq!(on.len(), 13 * 5, "{on:?}");
    assert!(on.iter().all(|n| n[1] == 0 && n[0] <= 12 && n[2] <= 4), "{on:?}");
}

/// The embankment with its base fixed by the mesh's "bottom" face gives the history of the same
/// base given as a box of nodes (y = 0, 0 ≤ x ≤ 6), exactly.
#[test]
fn a_mesh_boundary_fixes_what_the_same_box_fixes() {
    let run = |label: &str, base: &str| {
        let dir = std::env::temp_dir().join(format!("porompm-embankment-base-{label}"));
        let set = format!("boundaries.base={{name=\"base\",{base},fix=[\"ux\",\"uy\",\"uz\"]}}");
        let r = common::run_case("tests/cases/embankment_mesh_3d.toml", &dir, &common::set_args(&[&set]));
        assert!(r.completed(), "{label}: {}", r.stderr());
        r.rows
    };
    let mesh = run("mesh", "mesh={file=\"../meshes/embankment.msh\",group=\"bottom\"}");
    let region = run("region", "region={min=[0.0,0.0],max=[6.0,0.0],z=[0.0,2.0]}");
    assert_eq!(mesh, region);
}

/// A surface pressure pushes into the material whichever way its faces are numbered: on the top
/// of a box, a face whose area vector points up (away from the material) and one whose vector points
/// down (into it) both press down with their area; a face inside the box or in the empty grid is
/// refused, naming the side.
#[test]
fn a_surface_pressure_pushes_into_the_material_whichever_way_its_faces_turn() {
    use porompm::model::loads::surface_pressure_points;
    let boxed = body("b", "{ rectangle = { min = [0.0, 0.0], max = [1.0, 1.0] } }") + "z = [0.0, 1.0]\n";
    let c = case("[2.0, 2.0, 2.0]", "[8, 8, 8]", &boxed, "").unwrap();
    let h = [0.25; 3];
    let top = [0.5, 1.0, 0.5];
    for area in [[0.0, 0.2, 0.0], [0.0, -0.2, 0.0]] {
        let points = surface_pressure_points::<3>(&c, &[(top, area)], h).unwrap();
        assert_eq!(points, vec![(top, [0.0, -0.2, 0.0])], "area vector {area:?}");
    }
    let inside = surface_pressure_points::<3>(&c, &[([0.5, 0.5, 0.5], [0.0, 0.2, 0.0])], h).unwrap_err();
    assert!(inside.contains("has material on both sides"), "{inside}");
    let outside = surface_pressure_points::<3>(&c, &[([1.5, 1.5, 1.5], [0.0, 0.2, 0.0])], h).unwrap_err();
    assert!(outside.contains("has material on neither side"), "{outside}");
}
