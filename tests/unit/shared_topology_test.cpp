// io::SharedTopology and io::topology_of (src/io/mesh_topology.hpp): within a scope the
// statistics and every writer get one topology; outside, each call builds its own; after
// let_go the next caller holds it alone, so dropping it frees it.
#include <gtest/gtest.h>

#include <memory>

#include "globemesh/mesh.hpp"
#include "globemesh/sphere.hpp"
#include "mesh_topology.hpp"

namespace {

using globemesh::Mesh;
namespace io = globemesh::io;

/// Two triangles sharing an edge (5 edges, 4 on the boundary).
Mesh two_triangles() {
    Mesh m;
    m.nodes = {globemesh::lonlat_to_vec(0, 0), globemesh::lonlat_to_vec(1, 0),
               globemesh::lonlat_to_vec(1, 1), globemesh::lonlat_to_vec(0, 1)};
    m.faces = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

TEST(SharedTopology, outside_a_scope_each_call_builds_its_own) {
    const Mesh m = two_triangles();
    const auto a = io::topology_of(m), b = io::topology_of(m);
    EXPECT_NE(a, b);
    EXPECT_EQ(a->edge_count(), 5u);
    EXPECT_EQ(b->boundary_edges.size(), 4u);
}

TEST(SharedTopology, within_a_scope_every_call_gets_the_one_built_first) {
    const Mesh m = two_triangles(), other = two_triangles();
    const io::SharedTopology scope(m);
    const std::weak_ptr<const io::MeshTopology> first = io::topology_of(m);
    ASSERT_FALSE(first.expired()); // the scope keeps it between the writers
    EXPECT_EQ(io::topology_of(m), first.lock());
    {
        const io::SharedTopology inner(m); // a writer's own scope joins the caller's
        EXPECT_EQ(io::topology_of(m), first.lock());
    }
    EXPECT_FALSE(first.expired());
    EXPECT_NE(io::topology_of(other), first.lock()); // another mesh is not this one's
}

TEST(SharedTopology, after_let_go_the_next_caller_holds_it_alone) {
    const Mesh m = two_triangles();
    const io::SharedTopology scope(m);
    std::weak_ptr<const io::MeshTopology> first = io::topology_of(m);
    io::SharedTopology::let_go(m);
    EXPECT_FALSE(first.expired()); // kept for the next caller
    auto last = io::topology_of(m);
    EXPECT_EQ(last, first.lock());
    last.reset();
    EXPECT_TRUE(first.expired()); // that caller freed it: the last writer's early release
}

TEST(SharedTopology, a_scope_ends_with_its_topology) {
    const Mesh m = two_triangles();
    std::weak_ptr<const io::MeshTopology> kept;
    {
        const io::SharedTopology scope(m);
        kept = io::topology_of(m);
        EXPECT_FALSE(kept.expired());
    }
    EXPECT_TRUE(kept.expired());
    EXPECT_NE(io::topology_of(m), io::topology_of(m));
}

} // namespace
