//! What an OBJ and its libraries made the loader skip or assume, counted as
//! it happens and said once per kind: an 11 MB file of a million unknown
//! keys gives one warning line with a count, not a million lines, and what
//! the tally keeps is bounded (at most [`EXAMPLES`] names per kind).

use crate::scene::text::quote;

/// Names a warning lists of one kind (keys, material names); the rest are
/// counted.
pub const EXAMPLES: usize = 8;

/// One kind of event: how often, and where first.
#[derive(Default)]
pub(super) struct Count {
    pub count: u64,
    /// Where it happened first ("scene.obj line 3", "m.mtl line 7: Kd 2 0 0").
    pub first: String,
}

impl Count {
    /// Counts one more; `at` says where (built only the first time).
    pub fn add(&mut self, at: impl FnOnce() -> String) {
        if self.count == 0 {
            self.first = at();
        }
        self.count += 1;
    }
}

/// One kind of event with a name each (an ignored key, an unknown
/// material): the first [`EXAMPLES`] names with their count and first
/// place, and how many other names and events there were.
#[derive(Default)]
pub(super) struct Named {
    items: Vec<(String, String, u64, &'static str)>,
    other_names: u64,
    other_count: u64,
    /// Names already counted among the others, up to a bound, so that a
    /// name seen again is not counted as another name; past the bound
    /// other names are estimated from events.
    others_seen: std::collections::HashSet<String>,
}

/// Distinct names beyond the listed ones that are remembered to count
/// them exactly (their bytes are bounded by the file's, but not kept past
/// this).
const OTHERS_REMEMBERED: usize = 4096;

impl Named {
    /// Counts `name` once more; `at` says where, `why` is kept with its
    /// first event.
    pub fn add(&mut self, name: &str, why: &'static str, at: impl FnOnce() -> String) {
        if let Some(item) = self.items.iter_mut().find(|i| i.0 == name) {
            item.2 += 1;
            return;
        }
        if self.items.len() < EXAMPLES {
            self.items.push((name.to_string(), at(), 1, why));
            return;
        }
        self.other_count += 1;
        if self.others_seen.len() < OTHERS_REMEMBERED {
            if self.others_seen.insert(name.to_string()) {
                self.other_names += 1;
            }
        } else if !self.others_seen.contains(name) {
            self.other_names += 1;
        }
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// ": 'Ns' (m.mtl line 3, and 9 more), ..., and 5 other name(s) (12
    /// time(s))", with the reasons kept with the names: once before them
    /// all when they share one (" (why): 'Ns' ..."), else with each name.
    pub fn said(&self) -> String {
        let shared = self
            .items
            .first()
            .map(|i| i.3)
            .filter(|why| self.items.iter().all(|i| i.3 == *why));
        let mut parts: Vec<String> = self
            .items
            .iter()
            .map(|(name, at, count, why)| {
                let why = match shared {
                    None if !why.is_empty() => format!("; {why}"),
                    _ => String::new(),
                };
                format!("'{}' ({at}{}{why})", quote(name), more(*count))
            })
            .collect();
        if self.other_names > 0 {
            parts.push(format!(
                "and {} other name(s) ({} time(s))",
                self.other_names, self.other_count
            ));
        }
        match shared {
            Some(why) if !why.is_empty() => format!(" ({why}): {}", parts.join(", ")),
            _ => format!(": {}", parts.join(", ")),
        }
    }
}

/// ", and N more" for a count of N + 1 events.
pub(super) fn more(count: u64) -> String {
    if count > 1 {
        format!(", and {} more", count - 1)
    } else {
        String::new()
    }
}

/// Every kind the OBJ loader warns about.
#[derive(Default)]
pub(super) struct Tally {
    /// OBJ statements not rendered (`l`, `s`, free-form geometry, unknown).
    pub ignored_statements: Named,
    /// MTL keys not read (`Ns`, `illum`, unknown ones).
    pub ignored_keys: Named,
    /// `usemtl` names no library defines.
    pub unknown_materials: Named,
    /// A `newmtl` whose name an earlier one of the same library has.
    pub duplicate_materials: Count,
    /// `Kd` above 1, clamped.
    pub kd_above_one: Count,
    /// `map_Kd` options (`-s`, `-o`, ...) not applied.
    pub map_options: Count,
    /// `vn 0 0 0` (or a normal too small to have a direction).
    pub zero_normals: Count,
    /// Faces naming a normal at some corners only.
    pub partial_normals: Count,
    /// Faces wound against their normals, turned.
    pub rewound: Count,
    /// Faces naming texture coordinates at some corners only.
    pub partial_texcoords: Count,
    /// Triangles of zero area (or using a vertex twice), skipped.
    pub degenerate: u64,
    /// Triangles whose normals were computed.
    pub computed: u64,
}
