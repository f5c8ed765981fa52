// A directed graph whose nodes place the nodes their edges lead to (COLLADA nodes instancing
// nodes, SDF files including files), expanded by its counts alone: what each node places in
// all, every placement counted, and how deep its placements nest; or the cycle that would place
// without end. Memory and time linear in the graph, no recursion, whatever the expansion.
// Private to the core.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace onedof_sim {
namespace core {

// a + b, held at a value far above every limit and far below overflow.
size_t saturatingAdd(size_t a, size_t b);

struct ExpansionGraph {
  // Per node: the nodes it places, each placement once (a node placed twice is listed twice).
  std::vector<std::vector<size_t>> edges;
  // Per node: two counts of its own (triangles and placements, models and files, ...).
  std::vector<std::array<size_t, 2>> own;
};

struct Expansion {
  // The nodes around a cycle, its first node again at the end; empty when there is none (and
  // then the rest is filled).
  std::vector<size_t> cycle;
  // Per node: its own counts plus the totals of every node it places (saturating).
  std::vector<std::array<size_t, 2>> totals;
  // Per node: 1 + the deepest of the nodes it places.
  std::vector<size_t> depth;
};

Expansion expand(const ExpansionGraph& graph);

}  // namespace core
}  // namespace onedof_sim
