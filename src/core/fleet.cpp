#include "fleet.h"

#include <stdexcept>

namespace tender {

const std::vector<std::string>& topologyKeys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const ParamInfo& info : paramKeys())
      if (info.scope == ParamScope::Topology) k.push_back(info.key);
    return k;
  }();
  return keys;
}

std::optional<std::string> batchMismatch(const SimParams& a, const SimParams& b) {
  const auto va = paramValues(a), vb = paramValues(b);
  for (const std::string& key : topologyKeys())
    for (size_t k = 0; k < va.size(); ++k)
      if (va[k].first == key && va[k].second != vb[k].second)
        return "sheets of one batch share their topology, and " + key + " differs (" + va[k].second + " and " +
               vb[k].second + ")";
  return std::nullopt;
}

Fleet::Fleet(SheetBatch& batch, const std::vector<FleetSheet>& sheets) : batch_(batch) {
  if (sheets.size() != batch.size()) throw std::invalid_argument("a fleet needs one sheet per solver of its batch");
  for (const FleetSheet& s : sheets)
    if (auto why = batchMismatch(sheets.front().params, s.params)) throw std::invalid_argument(*why);
  sims_.reserve(sheets.size());
  for (uint32_t i = 0; i < sheets.size(); ++i) {
    sims_.push_back(std::make_unique<Simulation>(sheets[i].params, batch.sheet(i)));
    sims_.back()->setScript(sheets[i].script);
  }
}

void SheetBatch::readPositions(std::vector<glm::vec4>& pos, std::vector<glm::vec4>& prev) {
  pos.clear();
  prev.clear();
  SimState s;
  for (uint32_t i = 0; i < size(); ++i) {
    sheet(i).readback(s);
    pos.insert(pos.end(), s.pos.begin(), s.pos.end());
    prev.insert(prev.end(), s.prev.begin(), s.prev.end());
  }
}

void Fleet::tick() {
  // Every sheet's events first (a grab reads its particle back), then every sheet's tick queued
  for (auto& sim : sims_) sim->applyDueEvents();
  for (auto& sim : sims_) sim->tick();
  batch_.flush();
}

void QueuedSolver::upload(const SheetTopology& topo) {
  batch_.flush();
  inner_.upload(topo);
}

void QueuedSolver::tick(const shaderio::SimUniforms& u) {
  if (queued_) batch_.flush(); // a second tick of this sheet before the batch ran the first
  queued_ = u;
}

void QueuedSolver::beginReset() {
  batch_.flush();
  inner_.beginReset();
}

void QueuedSolver::computeNormals() {
  batch_.flush();
  inner_.computeNormals();
}

shaderio::PickResult QueuedSolver::pick(glm::vec3 o, glm::vec3 d, float radius) {
  batch_.flush();
  return inner_.pick(o, d, radius);
}

glm::vec3 QueuedSolver::particlePosition(uint32_t index) {
  batch_.flush();
  return inner_.particlePosition(index);
}

std::vector<glm::vec3> QueuedSolver::particlePositions(const std::vector<uint32_t>& indices) {
  batch_.flush();
  return inner_.particlePositions(indices);
}

void QueuedSolver::readback(SimState& out) {
  batch_.flush();
  inner_.readback(out);
}

void QueuedSolver::finish() {
  batch_.flush();
  batch_.finish();
}

void QueuedSolver::stopNextTickAfter(uint32_t last_pass) {
  batch_.flush();
  inner_.stopNextTickAfter(last_pass);
}

void QueuedSolver::readDeltas(std::vector<glm::vec4>& out) {
  batch_.flush();
  inner_.readDeltas(out);
}

} // namespace tender
