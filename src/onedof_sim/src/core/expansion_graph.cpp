#include "expansion_graph.h"

#include <algorithm>
#include <limits>
#include <utility>

namespace onedof_sim {
namespace core {

size_t saturatingAdd(size_t a, size_t b) {
  constexpr size_t kSaturated = std::numeric_limits<size_t>::max() / 4;
  return std::min(a + b, kSaturated);
}

Expansion expand(const ExpansionGraph& graph) {
  const size_t count = graph.edges.size();
  Expansion out;
  out.totals.assign(count, {0, 0});
  out.depth.assign(count, 0);
  enum class State { New, Open, Done };
  std::vector<State> state(count, State::New);
  // Depth-first, post-order, on a stack of its own: node, next edge.
  std::vector<std::pair<size_t, size_t>> stack;
  for (size_t start = 0; start < count; ++start) {
    if (state[start] != State::New) continue;
    stack.push_back({start, 0});
    state[start] = State::Open;
    while (!stack.empty()) {
      const size_t node = stack.back().first;
      size_t& next = stack.back().second;
      if (next < graph.edges[node].size()) {
        const size_t target = graph.edges[node][next++];
        if (state[target] == State::Open) {
          size_t from = 0;
          while (stack[from].first != target) ++from;
          for (size_t i = from; i < stack.size(); ++i) out.cycle.push_back(stack[i].first);
          out.cycle.push_back(target);
          return out;
        }
        if (state[target] == State::New) {
          state[target] = State::Open;
          stack.push_back({target, 0});
        }
        continue;
      }
      std::array<size_t, 2> totals = graph.own[node];
      size_t depth = 0;
      for (size_t target : graph.edges[node]) {
        for (size_t k = 0; k < 2; ++k) totals[k] = saturatingAdd(totals[k], out.totals[target][k]);
        depth = std::max(depth, out.depth[target]);
      }
      out.totals[node] = totals;
      out.depth[node] = depth + 1;
      state[node] = State::Done;
      stack.pop_back();
    }
  }
  return out;
}

}  // namespace core
}  // namespace onedof_sim
