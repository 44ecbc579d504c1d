//! Checks on the accessors a glTF mesh primitive is read through, made before the gltf crate
//! reads them.
//!
//! gltf 1.4 trusts the JSON when it iterates an accessor. It computes
//! `offset + stride × (count − 1) + size` unchecked, `debug_assert`s that the element size
//! matches, `assert`s that each strided slice holds an element, and reaches `unreachable!()` for
//! an index accessor of a signed or float type. Every one of those is a panic on a hostile file;
//! the fuzz target `gltf` found the last one. The checks here refuse such files with a message
//! naming the mesh, primitive and accessor. Each check is a rule of the glTF 2.0 specification:
//! §3.7.2.1 for index accessors (SCALAR, unsigned) and POSITION (VEC3 float); `count ≥ 1`; and
//! `byteStride` at least the element size. The offsets and counts are also capped at
//! [`MAX_MODEL_FILE_BYTES`], which no buffer can exceed, so the arithmetic cannot overflow.
//!
//! # Known limitations
//! Only the accessors the importer reads are checked: POSITION and indices.

use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;
use gltf::json::{Accessor, Root};

use crate::bounded_read::MAX_MODEL_FILE_BYTES;

/// A count or offset no buffer could hold.
fn too_big(value: u64) -> bool {
    value > MAX_MODEL_FILE_BYTES
}

/// Checks that every primitive's POSITION accessor index is in range (gltf-json 1.4 indexes it
/// unchecked in its own validation, so this runs before that).
pub(super) fn check_position_indices(json: &Root) -> Result<(), String> {
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions));
            if let Some(index) = position
                && index.value() >= accessors
            {
                return Err(format!(
                    "meshes[{m}].primitives[{p}].attributes.POSITION is accessor {}, but there are {accessors} accessors",
                    index.value()
                ));
            }
        }
    }
    Ok(())
}

/// Checks the POSITION and indices accessors of every primitive (after the crate's validation,
/// so every index is in range).
pub(super) fn check_primitive_accessors(json: &Root) -> Result<(), String> {
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let at = |what: &str| format!("meshes[{m}].primitives[{p}].{what}");
            if let Some(index) = primitive
                .attributes
                .get(&Checked::Valid(gltf::Semantic::Positions))
            {
                let accessor = get(json, index.value(), &at("attributes.POSITION"))?;
                let ok = matches!(&accessor.component_type, Checked::Valid(c) if c.0 == ComponentType::F32)
                    && accessor.type_ == Checked::Valid(Type::Vec3);
                if !ok {
                    return Err(format!(
                        "{} (accessor {}) must be VEC3 of FLOAT (5126)",
                        at("attributes.POSITION"),
                        index.value()
                    ));
                }
                check_layout(json, accessor, 12, &at("attributes.POSITION"))?;
            }
            if let Some(index) = &primitive.indices {
                let accessor = get(json, index.value(), &at("indices"))?;
                let size = match &accessor.component_type {
                    Checked::Valid(c) if c.0 == ComponentType::U8 => 1,
                    Checked::Valid(c) if c.0 == ComponentType::U16 => 2,
                    Checked::Valid(c) if c.0 == ComponentType::U32 => 4,
                    _ => 0,
                };
                if size == 0 || accessor.type_ != Checked::Valid(Type::Scalar) {
                    return Err(format!(
                        "{} (accessor {}) must be SCALAR of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT (5121, 5123, 5125)",
                        at("indices"),
                        index.value()
                    ));
                }
                check_layout(json, accessor, size, &at("indices"))?;
            }
        }
    }
    Ok(())
}

fn get<'a>(json: &'a Root, index: usize, what: &str) -> Result<&'a Accessor, String> {
    json.accessors.get(index).ok_or_else(|| {
        format!(
            "{what} is accessor {index}, but there are {} accessors",
            json.accessors.len()
        )
    })
}

/// `count ≥ 1`, counts and offsets within [`MAX_MODEL_FILE_BYTES`], and every buffer view the
/// accessor reads (its own, sparse indices, sparse values) with a stride of at least the element
/// size and an offset and length within the cap.
fn check_layout(
    json: &Root,
    accessor: &Accessor,
    element_bytes: usize,
    what: &str,
) -> Result<(), String> {
    let count = accessor.count.0;
    if count == 0 || too_big(count) {
        return Err(format!(
            "{what}: accessor count {count} is outside 1..={MAX_MODEL_FILE_BYTES}"
        ));
    }
    let offset = accessor.byte_offset.map_or(0, |o| o.0);
    if too_big(offset) {
        return Err(format!(
            "{what}: accessor byteOffset {offset} is past any buffer"
        ));
    }
    if let Some(view) = &accessor.buffer_view {
        check_view(json, view.value(), element_bytes, what)?;
    }
    if let Some(sparse) = &accessor.sparse {
        let n = sparse.count.0;
        if n == 0 || too_big(n) {
            return Err(format!(
                "{what}: sparse count {n} is outside 1..={MAX_MODEL_FILE_BYTES}"
            ));
        }
        for o in [sparse.indices.byte_offset.0, sparse.values.byte_offset.0] {
            if too_big(o) {
                return Err(format!("{what}: sparse byteOffset {o} is past any buffer"));
            }
        }
        let index_bytes = match &sparse.indices.component_type {
            Checked::Valid(c) if c.0 == ComponentType::U16 => 2,
            Checked::Valid(c) if c.0 == ComponentType::U32 => 4,
            _ => 1,
        };
        check_view(json, sparse.indices.buffer_view.value(), index_bytes, what)?;
        check_view(json, sparse.values.buffer_view.value(), element_bytes, what)?;
    }
    Ok(())
}

fn check_view(json: &Root, index: usize, element_bytes: usize, what: &str) -> Result<(), String> {
    let view = json.buffer_views.get(index).ok_or_else(|| {
        format!(
            "{what}: bufferView {index} does not exist ({} buffer views)",
            json.buffer_views.len()
        )
    })?;
    let (offset, length) = (view.byte_offset.map_or(0, |o| o.0), view.byte_length.0);
    if too_big(offset) || too_big(length) {
        return Err(format!(
            "{what}: bufferViews[{index}] byteOffset {offset} / byteLength {length} is past any buffer"
        ));
    }
    if let Some(stride) = view.byte_stride
        && stride.0 < element_bytes
    {
        return Err(format!(
            "{what}: bufferViews[{index}].byteStride {} is smaller than one element ({element_bytes} bytes)",
            stride.0
        ));
    }
    Ok(())
}
