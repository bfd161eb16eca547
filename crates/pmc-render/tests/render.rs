//! Renders synthetic closed meshes and checks coverage, lighting, the sea, errors and PNG output.

use std::collections::HashMap;

use pmc_geometry::glam::DVec3;
use pmc_mesh::ChunkMesh;
use pmc_render::{render, Camera, Image, RenderError, RenderOptions};

const R: f64 = 1000.0;
const SAND: [u8; 4] = [180, 150, 100, 255];

/// An icosphere of `radius` around the world origin with `levels` subdivisions, stored relative to
/// `origin`, counter-clockwise seen from outside, one colour.
fn icosphere(radius: f64, levels: u32, origin: DVec3, colour: [u8; 4]) -> ChunkMesh {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut verts: Vec<DVec3> = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut midpoint = |a: u32, b: u32, verts: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push((verts[a as usize] + verts[b as usize]).normalize());
                verts.len() as u32 - 1
            })
        };
        for [a, b, c] in faces {
            let ab = midpoint(a, b, &mut verts);
            let bc = midpoint(b, c, &mut verts);
            let ca = midpoint(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let mut m = ChunkMesh {
        origin,
        ..ChunkMesh::default()
    };
    for v in &verts {
        let p = *v * radius - origin;
        m.positions.push([p.x as f32, p.y as f32, p.z as f32]);
        m.normals.push([v.x as f32, v.y as f32, v.z as f32]);
        m.colors.push(colour);
        m.heights.push(0.0);
        m.water_depths.push(0.0);
        m.materials.push(0);
    }
    for [a, b, c] in faces {
        let (pa, pb, pc) = (verts[a as usize], verts[b as usize], verts[c as usize]);
        // Make every face counter-clockwise seen from outside.
        if (pb - pa).cross(pc - pa).dot(pa + pb + pc) > 0.0 {
            m.indices.extend([a, b, c]);
        } else {
            m.indices.extend([a, c, b]);
        }
    }
    m
}

fn small_opts() -> RenderOptions {
    RenderOptions {
        width: 320,
        height: 200,
        ..RenderOptions::default()
    }
}

/// Share of the screen covered by a sphere of `radius` seen head-on from `distance` (a disc of
/// radius `focal tan(asin(radius / distance))` pixels).
fn disc_fraction(radius: f64, distance: f64, camera: &Camera, opts: &RenderOptions) -> f64 {
    let focal = 0.5 * f64::from(opts.height) / (0.5 * camera.fov_deg).to_radians().tan();
    let r = focal * (radius / distance).asin().tan();
    std::f64::consts::PI * r * r / (f64::from(opts.width) * f64::from(opts.height))
}

/// Linear-light luminance of an sRGB pixel.
fn luminance(p: [u8; 4]) -> f64 {
    let lin = |c: u8| {
        let s = f64::from(c) / 255.0;
        if s <= 0.04045 {
            s / 12.92
        } else {
            ((s + 0.055) / 1.055).powf(2.4)
        }
    };
    0.2126 * lin(p[0]) + 0.7152 * lin(p[1]) + 0.0722 * lin(p[2])
}

/// Writes `image` under `PMC_RENDER_DUMP` when that variable names a folder (to look at).
fn dump(image: &Image, name: &str) {
    if let Some(dir) = std::env::var_os("PMC_RENDER_DUMP") {
        image
            .write_png(std::path::Path::new(&dir).join(format!("{name}.png")))
            .unwrap();
    }
}

#[test]
fn sphere_covers_its_disc() {
    let mesh = icosphere(R, 5, DVec3::new(0.0, 0.0, R), SAND);
    let opts = small_opts();
    for camera in [
        Camera::orbit(0.0, 0.0, 3.0 * R),
        Camera::orbit(35.0, -120.0, 4.0 * R),
        Camera::orbit(90.0, 0.0, 3.0 * R),
    ] {
        let image = render(std::slice::from_ref(&mesh), &camera, &opts).unwrap();
        dump(&image, &format!("sphere_{}_{}", camera.lat, camera.lon));
        let fraction = image.foreground_fraction(opts.background);
        let solid = disc_fraction(R, camera.distance, &camera, &opts);
        // The thin atmosphere (2% of the radius) may add a lit ring outside the disc.
        let with_rim = disc_fraction(1.02 * R, camera.distance, &camera, &opts);
        assert!(
            fraction > 0.97 * solid && fraction < 1.01 * with_rim,
            "{camera:?}: fraction {fraction}, disc {solid}, with rim {with_rim}"
        );
        // The middle is terrain, the corners are space.
        let centre = image.pixel(opts.width / 2, opts.height / 2);
        assert_ne!(centre[..3], opts.background);
        assert_eq!(image.pixel(0, 0)[..3], opts.background);
        assert_eq!(image.pixel(opts.width - 1, opts.height - 1)[..3], opts.background);
    }
}

#[test]
fn lit_side_is_brighter() {
    let mesh = icosphere(R, 4, DVec3::ZERO, SAND);
    // Camera on +Z: +X is to the right. Sun from the left.
    let opts = RenderOptions {
        sun_dir: DVec3::new(-1.0, 0.0, 0.0),
        ..small_opts()
    };
    let image = render(&[mesh], &Camera::orbit(0.0, 0.0, 3.0 * R), &opts).unwrap();
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for y in 0..opts.height {
        for x in 0..opts.width {
            let p = image.pixel(x, y);
            if p[..3] == opts.background {
                continue;
            }
            if x < opts.width / 2 - 10 {
                left.push(luminance(p));
            } else if x > opts.width / 2 + 10 {
                right.push(luminance(p));
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    assert!(left.len() > 1000 && right.len() > 1000);
    let (l, r) = (mean(&left), mean(&right));
    dump(&image, "lit_side");
    assert!(l > 2.0 * r, "left {l} right {r}");
}

#[test]
fn sea_above_the_terrain_is_blue() {
    let mesh = icosphere(R, 4, DVec3::ZERO, SAND);
    let camera = Camera::orbit(10.0, 20.0, 3.0 * R);
    let dry = render(std::slice::from_ref(&mesh), &camera, &small_opts()).unwrap();
    let (cx, cy) = (160, 100);
    let p = dry.pixel(cx, cy);
    assert!(p[0] > p[2], "sand is not blue: {p:?}");

    let wet = render(
        std::slice::from_ref(&mesh),
        &camera,
        &RenderOptions {
            sea_radius: Some(1.1 * R),
            ..small_opts()
        },
    )
    .unwrap();
    dump(&wet, "wet");
    let p = wet.pixel(cx, cy);
    assert!(p[2] > p[0] + 20 && p[2] > p[1], "sea is not blue: {p:?}");

    // A sea below the terrain stays hidden.
    let buried = render(
        &[mesh],
        &camera,
        &RenderOptions {
            sea_radius: Some(0.9 * R),
            ..small_opts()
        },
    )
    .unwrap();
    assert_eq!(buried.pixel(cx, cy), dry.pixel(cx, cy));
}

#[test]
fn shallow_sea_shows_the_floor() {
    // Terrain just under the sea at the centre of the view, deep elsewhere: the shallow water
    // keeps more of the sand colour than deep water does.
    let mesh = icosphere(R, 4, DVec3::ZERO, SAND);
    let camera = Camera::orbit(0.0, 0.0, 3.0 * R);
    let shallow = render(
        std::slice::from_ref(&mesh),
        &camera,
        &RenderOptions {
            sea_radius: Some(1.001 * R),
            ..small_opts()
        },
    )
    .unwrap();
    let deep = render(
        &[mesh],
        &camera,
        &RenderOptions {
            sea_radius: Some(1.2 * R),
            ..small_opts()
        },
    )
    .unwrap();
    dump(&shallow, "shallow");
    let (s, d) = (shallow.pixel(160, 100), deep.pixel(160, 100));
    assert!(s[0] > d[0] + 20, "shallow {s:?} deep {d:?}");
}

#[test]
fn back_faces_are_culled() {
    let tri = |indices: Vec<u32>| {
        let mut m = ChunkMesh {
            origin: DVec3::new(0.0, 0.0, R),
            ..ChunkMesh::default()
        };
        m.positions = vec![[-300.0, -300.0, 0.0], [300.0, -300.0, 0.0], [0.0, 300.0, 0.0]];
        m.colors = vec![SAND; 3];
        m.indices = indices;
        m
    };
    let camera = Camera::orbit(0.0, 0.0, 3.0 * R);
    let opts = small_opts();
    let front = render(&[tri(vec![0, 1, 2])], &camera, &opts).unwrap();
    assert!(front.foreground_fraction(opts.background) > 0.02);
    let back = render(&[tri(vec![0, 2, 1])], &camera, &opts).unwrap();
    dump(&front, "front_face");
    dump(&back, "back_face");
    // No atmosphere ring either: there is no terrain under the limb of the bounding sphere.
    assert_eq!(back.foreground_fraction(opts.background), 0.0);
}

#[test]
fn nearer_surface_wins() {
    // Two spheres on the line of sight: the small red one in front hides the big sand one.
    let near = icosphere(0.2 * R, 3, DVec3::ZERO, [255, 0, 0, 255]);
    // Moving the origin moves the mesh: this sphere is centred 1.5 R out on +Z.
    let near = ChunkMesh {
        origin: DVec3::new(0.0, 0.0, 1.5 * R),
        ..near
    };
    let far = icosphere(R, 4, DVec3::ZERO, SAND);
    let opts = RenderOptions {
        sun_dir: DVec3::Z,
        ..small_opts()
    };
    for meshes in [[near.clone(), far.clone()], [far, near]] {
        let image = render(&meshes, &Camera::orbit(0.0, 0.0, 4.0 * R), &opts).unwrap();
        let p = image.pixel(160, 100);
        assert!(p[0] > 200 && p[1] < 40, "{p:?}");
    }
}

#[test]
fn camera_inside_or_over_a_pole_is_fine() {
    let mesh = icosphere(R, 3, DVec3::ZERO, SAND);
    let opts = small_opts();
    // Inside the sphere every face is a back face.
    let inside = render(std::slice::from_ref(&mesh), &Camera::orbit(0.0, 0.0, 0.5 * R), &opts).unwrap();
    assert_eq!(inside.rgba.len(), 320 * 200 * 4);
    let pole = render(std::slice::from_ref(&mesh), &Camera::orbit(-90.0, 45.0, 3.0 * R), &opts).unwrap();
    assert!(pole.foreground_fraction(opts.background) > 0.2);
    // Close to the ground, looking at the horizon: triangles behind the camera are dropped.
    let low = Camera::orbit(0.0, 0.0, 1.05 * R).with_look_at(DVec3::new(0.0, 0.0, -R));
    assert!(render(&[mesh], &low, &opts).is_ok());
    // Nothing at all.
    let empty = render(&[], &Camera::orbit(0.0, 0.0, 3.0 * R), &opts).unwrap();
    assert_eq!(empty.foreground_fraction(opts.background), 0.0);
}

#[test]
fn meshes_without_attributes_render() {
    let mut mesh = icosphere(R, 2, DVec3::ZERO, SAND);
    mesh.normals.clear();
    mesh.colors.clear();
    let opts = small_opts();
    let image = render(&[mesh], &Camera::orbit(0.0, 0.0, 3.0 * R), &opts).unwrap();
    assert!(image.foreground_fraction(opts.background) > 0.2);
}

#[test]
fn bad_input_is_an_error() {
    let mesh = icosphere(R, 1, DVec3::ZERO, SAND);
    let camera = Camera::orbit(0.0, 0.0, 3.0 * R);
    let meshes = std::slice::from_ref(&mesh);
    let size = |width, height| {
        render(
            meshes,
            &camera,
            &RenderOptions {
                width,
                height,
                ..small_opts()
            },
        )
    };
    assert!(matches!(size(0, 10), Err(RenderError::Size { .. })));
    assert!(matches!(size(10, 0), Err(RenderError::Size { .. })));
    assert!(matches!(size(16385, 10), Err(RenderError::Size { .. })));
    assert!(matches!(size(10, 20000), Err(RenderError::Size { .. })));

    let cam = |c: Camera| render(meshes, &c, &small_opts());
    assert!(matches!(
        cam(Camera::orbit(f64::NAN, 0.0, 3.0 * R)),
        Err(RenderError::Camera(_))
    ));
    assert!(matches!(
        cam(Camera::orbit(0.0, f64::NAN, 3.0 * R)),
        Err(RenderError::Camera(_))
    ));
    assert!(matches!(
        cam(Camera::orbit(0.0, 0.0, f64::INFINITY)),
        Err(RenderError::Camera(_))
    ));
    assert!(matches!(cam(camera.with_fov(f64::NAN)), Err(RenderError::Camera(_))));
    assert!(matches!(cam(camera.with_fov(0.0)), Err(RenderError::Camera(_))));
    assert!(matches!(
        cam(camera.with_look_at(DVec3::splat(f64::NAN))),
        Err(RenderError::Camera(_))
    ));
    assert!(matches!(
        cam(camera.with_look_at(camera.eye())),
        Err(RenderError::Camera(_))
    ));

    let opt = |o: RenderOptions| render(meshes, &camera, &o);
    assert!(matches!(
        opt(RenderOptions {
            sun_dir: DVec3::ZERO,
            ..small_opts()
        }),
        Err(RenderError::Options(_))
    ));
    assert!(matches!(
        opt(RenderOptions {
            sun_dir: DVec3::NAN,
            ..small_opts()
        }),
        Err(RenderError::Options(_))
    ));
    assert!(matches!(
        opt(RenderOptions {
            sea_radius: Some(f64::NAN),
            ..small_opts()
        }),
        Err(RenderError::Options(_))
    ));
    assert!(matches!(
        opt(RenderOptions {
            sea_radius: Some(-1.0),
            ..small_opts()
        }),
        Err(RenderError::Options(_))
    ));

    let mut broken = mesh.clone();
    broken.indices.push(0);
    let err = render(&[mesh.clone(), broken], &camera, &small_opts()).unwrap_err();
    assert!(matches!(err, RenderError::Mesh { mesh: 1, .. }), "{err}");
    let mut broken = mesh.clone();
    broken.indices[4] = broken.positions.len() as u32;
    assert!(matches!(
        render(&[broken], &camera, &small_opts()),
        Err(RenderError::Mesh { mesh: 0, .. })
    ));
}

fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("pmc-render-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn png_round_trips() {
    let mesh = icosphere(R, 3, DVec3::ZERO, SAND);
    let opts = RenderOptions {
        width: 97,
        height: 61,
        ..RenderOptions::default()
    };
    let image = render(&[mesh], &Camera::framing(20.0, 30.0, R), &opts).unwrap();
    let dir = temp_dir("png");
    let path = dir.join("planet.png");
    image.write_png(&path).unwrap();
    // Overwriting works too, and leaves no temporary file behind.
    image.write_png(&path).unwrap();
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);

    let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (97, 61));
    assert_eq!(info.color_type, png::ColorType::Rgba);
    assert_eq!(&buf[..info.buffer_size()], &image.rgba[..]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn png_errors_name_the_path() {
    let image = Image {
        width: 2,
        height: 2,
        rgba: vec![0; 16],
    };
    let dir = temp_dir("missing");
    let err = image.write_png(dir.join("no/such/dir/out.png")).unwrap_err();
    assert!(matches!(err, RenderError::Io { .. }));
    assert!(err.to_string().contains("no/such/dir/out.png"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();

    let wrong = Image {
        width: 3,
        height: 2,
        rgba: vec![0; 16],
    };
    let dir = temp_dir("wrong");
    let err = wrong.write_png(dir.join("bad.png")).unwrap_err();
    assert!(err.to_string().contains("bad.png"), "{err}");
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "temporary file left behind"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
