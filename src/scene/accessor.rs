//! Reading glTF accessors (plain and sparse) into vectors, with every offset,
//! stride and count checked against the data that is really there.
//!
//! The `gltf` crate's reader is not used: it reads POSITION as f32 whatever the
//! component type says, computes `count - 1` and `stride * count` unchecked,
//! and never ends a sparse accessor without a buffer view.

use anyhow::{bail, Result};
use gltf::accessor::{DataType, Dimensions};

/// The glTF name of a component type, for messages.
pub fn type_name(t: DataType) -> &'static str {
    match t {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    }
}

pub fn dims_name(d: Dimensions) -> &'static str {
    match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

fn dims_count(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// "FLOAT VEC3", "normalized UNSIGNED_BYTE VEC2".
pub fn format_name(acc: &gltf::Accessor) -> String {
    format!(
        "{}{} {}",
        if acc.normalized() { "normalized " } else { "" },
        type_name(acc.data_type()),
        dims_name(acc.dimensions())
    )
}

/// One component as f32: floats as they are, normalized integers mapped to
/// [0, 1] or [-1, 1] as the glTF spec says, other integers by value.
fn decode(t: DataType, normalized: bool, b: &[u8]) -> f32 {
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, true) => b[0] as f32 / 255.0,
        (DataType::U8, false) => b[0] as f32,
        (DataType::I8, true) => (b[0] as i8 as f32 / 127.0).max(-1.0),
        (DataType::I8, false) => b[0] as i8 as f32,
        (DataType::U16, true) => u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0,
        (DataType::U16, false) => u16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::I16, true) => (i16::from_le_bytes([b[0], b[1]]) as f32 / 32767.0).max(-1.0),
        (DataType::I16, false) => i16::from_le_bytes([b[0], b[1]]) as f32,
        (DataType::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

fn decode_u32(t: DataType, b: &[u8]) -> u32 {
    match t {
        DataType::U8 => b[0] as u32,
        DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    }
}

/// The bytes of `count` elements of `elem` bytes at `offset` in `view`, and
/// the stride between them; an error if any of it lies outside the view or the
/// view outside its buffer.
fn view_elements<'b>(
    what: &str,
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    elem: usize,
    buffers: &'b [Vec<u8>],
) -> Result<(&'b [u8], usize)> {
    let Some(buffer) = buffers.get(view.buffer().index()) else {
        bail!(
            "{what}: buffer view {} names buffer {}, which does not exist",
            view.index(),
            view.buffer().index()
        );
    };
    let (start, len) = (view.offset(), view.length());
    if start.checked_add(len).is_none_or(|end| end > buffer.len()) {
        bail!(
            "{what}: buffer view {} (bytes {start}..+{len}) lies outside buffer {}, which has {} bytes (truncated?)",
            view.index(),
            view.buffer().index(),
            buffer.len()
        );
    }
    let stride = view.stride().unwrap_or(elem);
    if stride < elem {
        bail!(
            "{what}: buffer view {} has byteStride {stride}, less than the {elem}-byte element",
            view.index()
        );
    }
    if count == 0 {
        return Ok((&[], stride));
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(elem))
        .and_then(|n| n.checked_add(offset));
    match end {
        Some(end) if end <= len => Ok((&buffer[start + offset..start + end], stride)),
        _ => bail!(
            "{what}: {count} elements of {elem} bytes (stride {stride}) from byte {offset} do not fit in buffer view {}, which has {len} bytes (truncated?)",
            view.index()
        ),
    }
}

/// Elements of `acc` with `N` components each, as f32: the base data (zeros
/// without a buffer view), then the sparse substitutions. The caller has
/// checked the type and that `count` is within the budget.
pub fn read_f32<const N: usize>(
    what: &str,
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>> {
    let (t, norm) = (acc.data_type(), acc.normalized());
    if dims_count(acc.dimensions()) != N {
        bail!(
            "{what}: expected {N} components, the accessor has {}",
            format_name(acc)
        );
    }
    let size = t.size();
    let elem = size * N;
    let count = acc.count();
    let read = |bytes: &[u8]| -> [f32; N] {
        std::array::from_fn(|c| decode(t, norm, &bytes[c * size..(c + 1) * size]))
    };
    let mut out = vec![[0f32; N]; count];
    if let Some(view) = acc.view() {
        let (data, stride) = view_elements(what, &view, acc.offset(), count, elem, buffers)?;
        for (i, v) in out.iter_mut().enumerate() {
            *v = read(&data[i * stride..i * stride + elem]);
        }
    } else if acc.sparse().is_none() {
        bail!(
            "{what}: accessor {} has neither a buffer view nor sparse values",
            acc.index()
        );
    }
    if let Some(sparse) = acc.sparse() {
        apply_sparse(what, acc, &sparse, buffers, elem, |i, bytes| {
            out[i] = read(bytes)
        })?;
    }
    Ok(out)
}

/// Elements of an unsigned-integer SCALAR accessor (indices), sparse or not.
pub fn read_u32(what: &str, acc: &gltf::Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>> {
    let t = acc.data_type();
    if !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
        || acc.dimensions() != Dimensions::Scalar
    {
        bail!(
            "{what}: expected an unsigned integer SCALAR accessor, found {}",
            format_name(acc)
        );
    }
    let elem = t.size();
    let count = acc.count();
    let mut out = vec![0u32; count];
    if let Some(view) = acc.view() {
        let (data, stride) = view_elements(what, &view, acc.offset(), count, elem, buffers)?;
        for (i, v) in out.iter_mut().enumerate() {
            *v = decode_u32(t, &data[i * stride..i * stride + elem]);
        }
    } else if acc.sparse().is_none() {
        bail!(
            "{what}: accessor {} has neither a buffer view nor sparse values",
            acc.index()
        );
    }
    if let Some(sparse) = acc.sparse() {
        apply_sparse(what, acc, &sparse, buffers, elem, |i, bytes| {
            out[i] = decode_u32(t, bytes)
        })?;
    }
    Ok(out)
}

/// Calls `set(index, value bytes)` for each sparse substitution, after checking
/// that the indices are in range and strictly increasing (the spec).
fn apply_sparse(
    what: &str,
    acc: &gltf::Accessor,
    sparse: &gltf::accessor::sparse::Sparse,
    buffers: &[Vec<u8>],
    elem: usize,
    mut set: impl FnMut(usize, &[u8]),
) -> Result<()> {
    let n = sparse.count();
    if n > acc.count() {
        bail!(
            "{what}: accessor {} has {n} sparse values for {} elements",
            acc.index(),
            acc.count()
        );
    }
    let indices = sparse.indices();
    // `Gltf::from_slice` leaves the index type unchecked; `load` checks it
    // before this runs (`index_type` would panic on a signed or float type).
    let itype = match indices.index_type() {
        gltf::accessor::sparse::IndexType::U8 => DataType::U8,
        gltf::accessor::sparse::IndexType::U16 => DataType::U16,
        gltf::accessor::sparse::IndexType::U32 => DataType::U32,
    };
    let isize = itype.size();
    let (idata, istride) =
        view_elements(what, &indices.view(), indices.offset(), n, isize, buffers)?;
    let values = sparse.values();
    let (vdata, vstride) = view_elements(what, &values.view(), values.offset(), n, elem, buffers)?;
    let mut previous: Option<u32> = None;
    for k in 0..n {
        let i = decode_u32(itype, &idata[k * istride..k * istride + isize]);
        if i as usize >= acc.count() {
            bail!(
                "{what}: sparse index {i} of accessor {} is out of range for {} elements",
                acc.index(),
                acc.count()
            );
        }
        if previous.is_some_and(|p| i <= p) {
            bail!(
                "{what}: the sparse indices of accessor {} are not strictly increasing",
                acc.index()
            );
        }
        previous = Some(i);
        set(i as usize, &vdata[k * vstride..k * vstride + elem]);
    }
    Ok(())
}
