use super::*;

fn solid(name: &str, width: u32, height: u32) -> Texture {
    Texture {
        name: name.into(),
        width,
        height,
        rgba8: vec![200; width as usize * height as usize * 4],
    }
}

/// Every texture is in exactly one layer of an array at least its size.
fn assert_consistent(plan: &TexturePlan, textures: &[Texture]) {
    assert!(plan.arrays.len() <= ARRAYS);
    assert_eq!(plan.placements.len(), textures.len());
    for (i, p) in plan.placements.iter().enumerate() {
        let a = &plan.arrays[p.array as usize];
        assert_eq!(a.textures[p.layer as usize], i);
        let (w, h) = plan.sizes[i];
        assert!(
            a.width >= w && a.height >= h,
            "texture {i} {w}x{h} in {a:?}"
        );
    }
    for a in &plan.arrays {
        assert!(!a.textures.is_empty() && a.textures.len() <= MAX_LAYERS);
        assert!(a.width <= MAX_SIDE && a.height <= MAX_SIDE);
    }
}

#[test]
fn textures_of_few_sizes_get_an_array_of_their_own_size_each() {
    let textures = [
        solid("a", 64, 32),
        solid("b", 16, 16),
        solid("c", 64, 32),
        solid("d", 3, 5),
    ];
    // No padding allowed: no join past the arrays' number.
    let plan = TexturePlan::with_padding(&textures, 0).unwrap();
    assert_consistent(&plan, &textures);
    let sizes: Vec<(u32, u32, usize)> = plan
        .arrays
        .iter()
        .map(|a| (a.width, a.height, a.textures.len()))
        .collect();
    assert_eq!(sizes, [(3, 5, 1), (16, 16, 1), (64, 32, 2)]);
    // Nothing is padded: the arrays hold exactly the textures' texels.
    assert_eq!(plan.bytes(), (64 * 32 * 2 + 16 * 16 + 3 * 5) * 4);
    // With the default padding, so few texels join into one array.
    let one = TexturePlan::new(&textures).unwrap();
    assert_consistent(&one, &textures);
    assert_eq!(one.arrays.len(), 1);
    assert_eq!((one.arrays[0].width, one.arrays[0].height), (66, 34));
    assert_eq!(
        TexturePlan::new(&[]).unwrap().arrays,
        Vec::<ArrayPlan>::new()
    );
}

/// Sponza's ten sizes (the textures its MTL uses): two joins, each the
/// cheapest.
#[test]
fn more_sizes_than_arrays_join_the_groups_that_add_fewest_texels() {
    let sizes = [
        (903, 99),
        (1024, 704),
        (155, 23),
        (640, 477),
        (305, 357),
        (294, 251),
        (1021, 150),
        (410, 489),
        (423, 807),
        (207, 477),
    ];
    let textures: Vec<Texture> = sizes
        .iter()
        .map(|&(w, h)| solid(&format!("{w}x{h}"), w, h))
        .collect();
    let plan = TexturePlan::with_padding(&textures, 0).unwrap();
    assert_consistent(&plan, &textures);
    assert_eq!(plan.arrays.len(), ARRAYS);
    let own: u64 = sizes.iter().map(|&(w, h)| w as u64 * h as u64 * 4).sum();
    // 294x251 joins 305x357 in bordered 307x359 layers (37,747 texels
    // more), then 903x99 joins 1021x150 in 1023x152 ones (68,445 more):
    // 5.1% over the textures' own 8.0 MiB, 8.4 MiB in all. One array of ten
    // bordered 1026x809 layers would take 31.7 MiB.
    assert_eq!(plan.bytes() - own, (37_747 + 68_445) * 4);
    let a = |i: usize| &plan.arrays[plan.placements[i].array as usize];
    assert_eq!((a(5).width, a(5).height), (307, 359));
    assert_eq!((a(0).width, a(0).height), (1023, 152));
    assert_eq!((a(2).width, a(2).height), (155, 23));
    assert_eq!(a(5), a(4));
    assert_eq!(a(0), a(6));
    // By default Sponza's 2.1 M texels may add 16 M: one array of ten
    // bordered 1026x809 layers.
    let one = TexturePlan::new(&textures).unwrap();
    assert_consistent(&one, &textures);
    assert_eq!(one.arrays.len(), 1);
    assert_eq!(one.bytes(), 1026 * 809 * 10 * 4);
    // Padding of at most the textures' own 2.1 M texels: 4 arrays of 12.1
    // MiB in all (3 would take 16.1 MiB, over the 16.0 allowed).
    let four = TexturePlan::with_padding(&textures, own / 4).unwrap();
    assert_consistent(&four, &textures);
    assert_eq!(four.arrays.len(), 4);
    assert!(four.bytes() - own <= own, "{}", four.bytes());
}

#[test]
fn a_size_with_more_textures_than_layers_takes_several_arrays() {
    let textures: Vec<Texture> = (0..MAX_LAYERS * 2 + 1)
        .map(|i| solid(&i.to_string(), 2, 2))
        .collect();
    let plan = TexturePlan::new(&textures).unwrap();
    assert_consistent(&plan, &textures);
    let layers: Vec<usize> = plan.arrays.iter().map(|a| a.textures.len()).collect();
    assert_eq!(layers, [MAX_LAYERS, MAX_LAYERS, 1]);
}

/// Many sizes (a hostile scene) are bounded work and still fit; too many
/// textures are an error that says the limit.
#[test]
fn many_sizes_fit_and_too_many_textures_are_refused() {
    let textures: Vec<Texture> = (0..ARRAYS * MAX_LAYERS)
        .map(|i| solid(&i.to_string(), 1 + (i % 61) as u32, 1 + (i % 53) as u32))
        .collect();
    let started = std::time::Instant::now();
    let plan = TexturePlan::new(&textures).unwrap();
    assert!(started.elapsed().as_secs_f64() < 2.0);
    assert_consistent(&plan, &textures);
    let mut more = textures;
    more.push(solid("one too many", 1, 1));
    let e = TexturePlan::new(&more).unwrap_err().to_string();
    assert!(
        e.contains("2049 textures") && e.contains("at most 2048"),
        "{e}"
    );
}

#[test]
fn pixels_that_do_not_match_the_size_are_an_error() {
    let mut t = solid("short", 4, 4);
    t.rgba8.pop();
    let e = TexturePlan::new(&[t]).unwrap_err().to_string();
    assert!(e.contains("texture short is 4x4 but holds 63 bytes"), "{e}");
    let e = TexturePlan::new(&[solid("empty", 0, 3)])
        .unwrap_err()
        .to_string();
    assert!(e.contains("texture empty is 0x3"), "{e}");
}

#[test]
fn only_a_texture_over_the_layer_side_is_shrunk_with_a_warning() {
    assert_eq!(fitted_size(4096, 4096), (4096, 4096));
    assert_eq!(fitted_size(1, 4096), (1, 4096));
    assert_eq!(fitted_size(8192, 4096), (4096, 2048));
    assert_eq!(fitted_size(5000, 3), (4096, 2));
    assert_eq!(fitted_size(16384, 1), (4096, 1));
    let textures = [solid("big", 4100, 2), solid("fine", 4096, 7)];
    let w = warnings(&textures);
    assert_eq!(w.len(), 1);
    assert!(
        w[0].contains("texture big is 4100x2") && w[0].contains("shrunk to 4096x2"),
        "{}",
        w[0]
    );
    let fitted = fitted(&textures);
    assert!(matches!(fitted[1], Cow::Borrowed(_)));
    assert_eq!((fitted[0].width, fitted[0].height), (4096, 2));
    assert_eq!(fitted[0].rgba8.len(), 4096 * 2 * 4);
    let plan = TexturePlan::new(&textures).unwrap();
    assert_eq!(plan.sizes, [(4096, 2), (4096, 7)]);
}

/// Shrunk textures are one warning however many: the first three by name.
#[test]
fn shrunk_textures_are_one_warning() {
    let textures: Vec<Texture> = (0..5).map(|i| solid(&format!("t{i}"), 4097, 1)).collect();
    let w = warnings(&textures);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains("5 texture(s)")
            && w[0].contains("texture t0 is 4097x1, shrunk to 4096x1; t1 is")
            && w[0].ends_with("; and 2 more"),
        "{}",
        w[0]
    );
}

/// Textures of shapes that join badly would be padded to thousands of
/// times their texels: 1000 long thin ones across and 1048 down need 4 + 5
/// arrays apart, so all 2048 share one of 4002 x 4002 layers (32 G texels
/// for their 8 M). Refused, within the decode budget, with what to do.
#[test]
fn arrays_that_would_pad_past_the_decode_budget_are_refused() {
    let textures: Vec<Texture> = (0..ARRAYS * MAX_LAYERS)
        .map(|i| match i < 1000 {
            true => solid(&i.to_string(), 4000, 1),
            false => solid(&i.to_string(), 1, 4000),
        })
        .collect();
    let e = TexturePlan::new(&textures).unwrap_err().to_string();
    assert!(
        e.contains("have 8192000 texels") && e.contains("too many different shapes"),
        "{e}"
    );
}
