//! Digests and comparisons of OpenEXR files, for checking that a change
//! leaves images bit-identical (`.ci/image-digests` runs it over every GPU
//! method):
//!
//! - `exr_digest FILE.exr` prints one 64-bit FNV-1a digest of every layer,
//!   channel and sample (bit patterns, in file order), whatever order the
//!   writer's threads put the compressed blocks in;
//! - `exr_digest --compare A.exr B.exr` prints the largest difference of any
//!   f32 sample relative to the peak of its channel, and exits non-zero if
//!   the files' layers or channels differ. Basic ISR needs this: its list is
//!   appended with an atomic counter, so the order of its sums, and the
//!   rounding of its images, change from run to run.

use anyhow::{bail, Result};
use exr::prelude::*;

type Channels = Vec<(String, Vec<f32>)>;

fn read(path: &str) -> Result<Channels> {
    let image = read_all_flat_layers_from_file(path)?;
    let mut out = Vec::new();
    for layer in &image.layer_data {
        let layer_name = layer.attributes.layer_name.as_ref().map(|n| n.to_string());
        for channel in &layer.channel_data.list {
            let name = format!(
                "{}.{}",
                layer_name.clone().unwrap_or_default(),
                channel.name
            );
            let samples = match &channel.sample_data {
                FlatSamples::F32(v) => v.clone(),
                FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
                FlatSamples::U32(v) => v.iter().map(|&x| f32::from_bits(x)).collect(),
            };
            out.push((name, samples));
        }
    }
    Ok(out)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [path] => {
            let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
            let mut eat = |bytes: &[u8]| {
                for &b in bytes {
                    hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
                }
            };
            for (name, samples) in read(path)? {
                eat(name.as_bytes());
                samples.iter().for_each(|x| eat(&x.to_bits().to_le_bytes()));
            }
            println!("{hash:016x}");
        }
        [flag, a, b] if flag == "--compare" => {
            let (a, b) = (read(a)?, read(b)?);
            if a.len() != b.len()
                || a.iter()
                    .zip(&b)
                    .any(|(x, y)| x.0 != y.0 || x.1.len() != y.1.len())
            {
                bail!("the two files have different layers, channels or sizes");
            }
            let mut worst = 0.0f64;
            for ((_, x), (_, y)) in a.iter().zip(&b) {
                let peak = x
                    .iter()
                    .chain(y)
                    .filter(|v| v.is_finite())
                    .fold(0.0f32, |m, v| m.max(v.abs()));
                for (p, q) in x.iter().zip(y) {
                    if p.to_bits() != q.to_bits() {
                        let d = (p - q).abs() as f64 / (peak as f64).max(f64::MIN_POSITIVE);
                        worst = worst.max(if d.is_finite() { d } else { f64::INFINITY });
                    }
                }
            }
            println!("{worst:e}");
        }
        _ => bail!("usage: exr_digest FILE.exr | exr_digest --compare A.exr B.exr"),
    }
    Ok(())
}
