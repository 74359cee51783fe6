// Passes at the output resolution: box mean, majority, Cryptomatte rank merge.
#include "pass_downsample.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <map>
#include <utility>

namespace dcm::cli {

namespace {

/// Calls f(outputIndex, inputIndices) for each output pixel's N x N box.
template <typename F>
void ForEachBox(int width, int height, int n, F&& f) {
  const int ow = width / n, oh = height / n;
  std::vector<size_t> box(size_t(n) * size_t(n));
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      size_t k = 0;
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) box[k++] = size_t(y * n + j) * size_t(width) + size_t(x * n + i);
      f(size_t(y) * size_t(ow) + size_t(x), box);
    }
}

template <typename T>
std::vector<T> Majority(const std::vector<T>& plane, int width, int height, int n) {
  std::vector<T> out(size_t(width / n) * size_t(height / n));
  ForEachBox(width, height, n, [&](size_t o, const std::vector<size_t>& box) {
    size_t best = 0, bestCount = 0;
    for (size_t a = 0; a < box.size(); ++a) {
      size_t count = 0;
      for (size_t b = 0; b < box.size(); ++b) count += std::bit_cast<uint32_t>(plane[box[a]]) ==
                                                       std::bit_cast<uint32_t>(plane[box[b]]);
      if (count > bestCount) best = a, bestCount = count;
    }
    out[o] = plane[box[best]];
  });
  return out;
}

/// The Cryptomatte layer `channel` belongs to: "<layer>NN.R|G|B|A".
bool InCryptoLayer(const std::string& channel, const std::string& layer, int* rank, int* component) {
  if (channel.size() != layer.size() + 4 || channel.compare(0, layer.size(), layer) != 0) return false;
  const char d0 = channel[layer.size()], d1 = channel[layer.size() + 1], dot = channel[layer.size() + 2];
  const std::string comps = "RGBA";
  const size_t c = comps.find(channel.back());
  if (!std::isdigit(static_cast<unsigned char>(d0)) || !std::isdigit(static_cast<unsigned char>(d1)) || dot != '.' ||
      c == std::string::npos)
    return false;
  *rank = (d0 - '0') * 10 + (d1 - '0');
  *component = int(c);
  return true;
}

}  // namespace

std::vector<float> BoxMeanPlane(const std::vector<float>& plane, int width, int height, int n) {
  std::vector<float> out(size_t(width / n) * size_t(height / n));
  // As dcm::BoxDownsample sums the beauty: in double, row by row, then / n^2.
  ForEachBox(width, height, n, [&](size_t o, const std::vector<size_t>& box) {
    double sum = 0;
    for (size_t i : box) sum += double(plane[i]);
    out[o] = float(sum / double(box.size()));
  });
  return out;
}

std::vector<uint32_t> MajorityPlane(const std::vector<uint32_t>& plane, int width, int height, int n) {
  return Majority(plane, width, height, n);
}

std::vector<float> MajorityPlane(const std::vector<float>& plane, int width, int height, int n) {
  return Majority(plane, width, height, n);
}

Status DownsampleCryptomatte(std::vector<std::vector<float>*> ranks, int width, int height, int n) {
  if (ranks.empty() || ranks.size() % 2 != 0)
    return Status::Error("a Cryptomatte layer needs (id, coverage) pairs, got " + std::to_string(ranks.size()) +
                         " channels");
  const size_t in = size_t(width) * size_t(height);
  for (const auto* c : ranks)
    if (c->size() != in) return Status::Error("a Cryptomatte channel has the wrong size");
  const size_t pairs = ranks.size() / 2;
  std::vector<std::vector<float>> out(ranks.size(), std::vector<float>(size_t(width / n) * size_t(height / n)));
  const float w = 1.f / float(n * n);
  std::vector<std::pair<uint32_t, float>> coverage;  // id bits, summed coverage
  ForEachBox(width, height, n, [&](size_t o, const std::vector<size_t>& box) {
    coverage.clear();
    for (size_t i : box)
      for (size_t r = 0; r < pairs; ++r) {
        const float cov = (*ranks[2 * r + 1])[i];
        if (!(cov > 0.f)) continue;  // an empty rank (0, 0) or garbage
        const uint32_t id = std::bit_cast<uint32_t>((*ranks[2 * r])[i]);
        auto it = std::find_if(coverage.begin(), coverage.end(), [&](const auto& e) { return e.first == id; });
        if (it == coverage.end()) coverage.emplace_back(id, cov);
        else it->second += cov;
      }
    // Most coverage first; equal coverage in the order first seen.
    std::stable_sort(coverage.begin(), coverage.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    for (size_t r = 0; r < pairs; ++r) {
      out[2 * r][o] = r < coverage.size() ? std::bit_cast<float>(coverage[r].first) : 0.f;
      out[2 * r + 1][o] = r < coverage.size() ? coverage[r].second * w : 0.f;
    }
  });
  for (size_t c = 0; c < ranks.size(); ++c) *ranks[c] = std::move(out[c]);
  return Status::Ok();
}

Status DownsamplePasses(std::vector<toolkit::OutputChannel>* channels, const std::vector<size_t>& passes,
                        const std::vector<std::string>& cryptoLayers, int width, int height, int n) {
  std::vector<bool> done(channels->size(), false);
  for (const std::string& layer : cryptoLayers) {
    std::map<int, std::vector<float>*> byIndex;  // rank * 4 + component
    for (size_t p : passes) {
      int rank = 0, comp = 0;
      if (!InCryptoLayer((*channels)[p].name, layer, &rank, &comp)) continue;
      byIndex[rank * 4 + comp] = &(*channels)[p].values;
      done[p] = true;
    }
    if (byIndex.empty()) continue;
    std::vector<std::vector<float>*> ordered;
    for (int k = 0; k < int(byIndex.size()); ++k) {
      auto it = byIndex.find(k);
      if (it == byIndex.end())
        return Status::Error("Cryptomatte layer '" + layer + "': channel " + std::to_string(k / 4) + "." +
                             "RGBA"[k % 4] + " missing; cannot combine its ranks for --downsample");
      ordered.push_back(it->second);
    }
    DCM_RETURN_IF_ERROR(DownsampleCryptomatte(ordered, width, height, n));
  }
  for (size_t p : passes) {
    if (done[p]) continue;
    toolkit::OutputChannel& ch = (*channels)[p];
    if (!ch.ids.empty()) ch.ids = MajorityPlane(ch.ids, width, height, n);
    else if (ch.raw) ch.values = MajorityPlane(ch.values, width, height, n);
    else ch.values = BoxMeanPlane(ch.values, width, height, n);
  }
  return Status::Ok();
}

}  // namespace dcm::cli
