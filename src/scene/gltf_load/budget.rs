//! The budgets, counted on the node graph before anything is instanced or
//! allocated.

use super::*;

/// What instancing the scene will produce, counted on the node graph before
/// any of it is done (saturating: a 40-level DAG counts 2^41 visits without
/// visiting them).
pub(super) struct Plan {
    visits: u64,
    triangles: u64,
    vertices: u64,
    depth: u64,
}

impl Plan {
    pub(super) fn check(&self, limits: &Limits) -> Result<()> {
        if self.depth > limits.hierarchy_depth {
            bail!(
                "the node hierarchy is {} levels deep; the limit is {}",
                self.depth,
                limits.hierarchy_depth
            );
        }
        if self.visits > limits.node_visits {
            bail!(
                "the node hierarchy expands to {} node instances (nodes listed under several parents are instanced once per path); the limit is {}",
                count(self.visits),
                limits.node_visits
            );
        }
        if self.triangles > limits.triangles {
            bail!(
                "the scene instances {} triangles; the limit is {}",
                count(self.triangles),
                limits.triangles
            );
        }
        if self.vertices > limits.vertices {
            bail!(
                "the scene instances {} vertices; the limit is {}",
                count(self.vertices),
                limits.vertices
            );
        }
        Ok(())
    }
}

pub(super) fn count(n: u64) -> String {
    if n == u64::MAX {
        "more than 2^64".into()
    } else {
        n.to_string()
    }
}

/// Per node: visits, triangles, vertices and depth of the subtree under it,
/// memoised over the graph (iterative: no recursion on hostile depth).
pub(super) fn measure(doc: &gltf::Document, scene: &gltf::Scene) -> Result<Plan> {
    // Triangles and vertices each mesh adds per instance, from accessor counts.
    let mesh_cost: Vec<(u64, u64)> = doc
        .meshes()
        .map(|m| {
            m.primitives()
                .filter(|p| p.mode() == gltf::mesh::Mode::Triangles)
                .fold((0u64, 0u64), |(t, v), p| {
                    let verts = p
                        .get(&gltf::Semantic::Positions)
                        .map_or(0, |a| a.count() as u64);
                    let ids = p.indices().map_or(verts, |a| a.count() as u64);
                    (t.saturating_add(ids / 3), v.saturating_add(verts))
                })
        })
        .collect();
    let n = doc.nodes().len();
    // None: not seen; Some(None): on the current path; Some(Some(plan)): done.
    let mut memo: Vec<Option<Option<Plan>>> = (0..n).map(|_| None).collect();
    let nodes: Vec<gltf::Node> = doc.nodes().collect();
    let mut total = Plan {
        visits: 0,
        triangles: 0,
        vertices: 0,
        depth: 0,
    };
    for root in scene.nodes() {
        let mut stack = vec![(root.index(), false)];
        while let Some((i, children_done)) = stack.pop() {
            if children_done {
                let node = &nodes[i];
                let (t, v) = node.mesh().map_or((0, 0), |m| mesh_cost[m.index()]);
                let mut p = Plan {
                    visits: 1,
                    triangles: t,
                    vertices: v,
                    depth: 1,
                };
                for c in node.children() {
                    if let Some(Some(cp)) = &memo[c.index()] {
                        p.visits = p.visits.saturating_add(cp.visits);
                        p.triangles = p.triangles.saturating_add(cp.triangles);
                        p.vertices = p.vertices.saturating_add(cp.vertices);
                        p.depth = p.depth.max(cp.depth.saturating_add(1));
                    }
                }
                memo[i] = Some(Some(p));
                continue;
            }
            match &memo[i] {
                Some(Some(_)) => continue,
                Some(None) => bail!("the node hierarchy has a cycle through node {i}"),
                None => {}
            }
            memo[i] = Some(None);
            stack.push((i, true));
            for c in nodes[i].children() {
                match &memo[c.index()] {
                    Some(None) => bail!(
                        "the node hierarchy has a cycle: node {} is its own ancestor",
                        c.index()
                    ),
                    Some(Some(_)) => {}
                    None => stack.push((c.index(), false)),
                }
            }
        }
        if let Some(Some(p)) = &memo[root.index()] {
            total.visits = total.visits.saturating_add(p.visits);
            total.triangles = total.triangles.saturating_add(p.triangles);
            total.vertices = total.vertices.saturating_add(p.vertices);
            total.depth = total.depth.max(p.depth);
        }
    }
    Ok(total)
}
