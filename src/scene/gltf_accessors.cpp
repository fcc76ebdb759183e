/// @file scene/gltf_accessors.cpp
/// @brief GltfReader (gltf_internal.h): glTF accessors read as doubles,
/// each checked to fit its bufferView and buffer, and every sparse index
/// to lie in range, before a byte is read.

#include "scene/gltf_internal.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace lo::scene_internal::gltf_internal {

std::vector<double> GltfReader::read(int index, int type, const std::string& what) const {
  if (index < 0 || size_t(index) >= model_.accessors.size()) {
    fail(path_, what + ": accessor index " + std::to_string(index) + " out of range (" +
                    std::to_string(model_.accessors.size()) + " accessors)");
  }
  const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
  std::string name = what + " (accessor " + std::to_string(index) + ")";
  if (acc.type != type) fail(path_, name + " has the wrong type " + std::to_string(acc.type));
  int comps = tinygltf::GetNumComponentsInType(uint32_t(type));
  int csize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
  if (comps <= 0 || csize <= 0) {
    fail(path_, name + " has an invalid component type " + std::to_string(acc.componentType));
  }
  if (acc.count > (size_t(1) << 28)) {
    fail(path_, name + " count " + std::to_string(acc.count) + " is out of range");
  }
  // Sizes are checked against the bytes that back them before anything is
  // allocated: a small file must not cost gigabytes (docs/robustness.md).
  size_t elemSize = size_t(comps) * size_t(csize);
  const unsigned char* data = nullptr;
  size_t stride = elemSize;
  if (acc.bufferView >= 0) {
    data = viewData(acc.bufferView, name);
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(acc.bufferView)];
    stride = bv.byteStride ? bv.byteStride : elemSize;
    if (stride < elemSize) {
      fail(path_, name + ": byteStride " + std::to_string(stride) +
                      " is smaller than the element size " + std::to_string(elemSize));
    }
    if (acc.count > 0) {
      uint64_t end = uint64_t(acc.byteOffset) + uint64_t(stride) * (acc.count - 1) + elemSize;
      if (end > bv.byteLength) {
        fail(path_, name + " is out of range of its bufferView " +
                        std::to_string(acc.bufferView) + " (needs " + std::to_string(end) +
                        " bytes, view has " + std::to_string(bv.byteLength) + ")");
      }
    }
  } else if (acc.sparse.isSparse) {
    // No bufferView: zeros but for the sparse values. Such an accessor may
    // hold at most kMaxImplicitElementsPerSparse elements per sparse value.
    const size_t limit =
        std::max<size_t>(kMinImplicitElements,
                         kMaxImplicitElementsPerSparse * size_t(std::max(0, acc.sparse.count)));
    if (acc.count > limit) {
      fail(path_, name + " has no bufferView: " + std::to_string(acc.count) +
                      " implicit zero elements for " + std::to_string(acc.sparse.count) +
                      " sparse values, more than the " + std::to_string(limit) + " allowed");
    }
  } else {
    // Refused before allocating: found by fuzz_gltf (2^28 elements, 6.4 GB).
    fail(path_, name + " has neither a bufferView nor sparse values");
  }
  std::vector<double> out(acc.count * size_t(comps), 0.0);
  if (data) {
    for (size_t e = 0; e < acc.count; ++e)
      for (int c = 0; c < comps; ++c)
        out[e * size_t(comps) + size_t(c)] =
            component(data + acc.byteOffset + e * stride + size_t(c) * size_t(csize),
                      acc.componentType, acc.normalized);
  }
  if (acc.sparse.isSparse) readSparse(acc, comps, csize, name, out);
  return out;
}

std::vector<uint32_t> GltfReader::readIndices(int index, const std::string& what) const {
  if (index >= 0 && size_t(index) < model_.accessors.size()) {
    int ct = model_.accessors[size_t(index)].componentType;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      fail(path_, what + " (accessor " + std::to_string(index) +
                      ") must hold unsigned integers, has component type " + std::to_string(ct));
    }
  }
  std::vector<double> v = read(index, TINYGLTF_TYPE_SCALAR, what);
  std::vector<uint32_t> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = uint32_t(v[i]);
  return out;
}

size_t GltfReader::count(int index) const {
  return index >= 0 && size_t(index) < model_.accessors.size()
             ? model_.accessors[size_t(index)].count
             : 0;
}

const unsigned char* GltfReader::viewData(int view, const std::string& name) const {
  if (view < 0 || size_t(view) >= model_.bufferViews.size()) {
    fail(path_, name + ": bufferView index " + std::to_string(view) + " out of range");
  }
  const tinygltf::BufferView& bv = model_.bufferViews[size_t(view)];
  if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size()) {
    fail(path_, name + ": buffer index " + std::to_string(bv.buffer) + " out of range");
  }
  const tinygltf::Buffer& buf = model_.buffers[size_t(bv.buffer)];
  if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
    fail(path_, name + ": bufferView " + std::to_string(view) + " is out of range of buffer " +
                    std::to_string(bv.buffer) + " (missing buffer data?)");
  }
  return buf.data.data() + bv.byteOffset;
}

void GltfReader::readSparse(const tinygltf::Accessor& acc, int comps, int csize,
                            const std::string& name, std::vector<double>& out) const {
  if (acc.sparse.count < 0 || size_t(acc.sparse.count) > acc.count) {
    fail(path_, name + ": sparse count out of range");
  }
  size_t n = size_t(acc.sparse.count);
  int ict = acc.sparse.indices.componentType;
  int isize = tinygltf::GetComponentSizeInBytes(uint32_t(ict));
  if (isize <= 0 || ict == TINYGLTF_COMPONENT_TYPE_FLOAT) {
    fail(path_, name + ": invalid sparse index component type");
  }
  auto fits = [&](int view, int offset, size_t bytes) {
    if (offset < 0) fail(path_, name + ": negative sparse byteOffset");
    const unsigned char* d = viewData(view, name + " sparse");
    if (uint64_t(offset) + bytes > model_.bufferViews[size_t(view)].byteLength) {
      fail(path_, name + ": sparse data out of range of bufferView " + std::to_string(view));
    }
    return d + offset;
  };
  const unsigned char* idx =
      fits(acc.sparse.indices.bufferView, acc.sparse.indices.byteOffset, n * size_t(isize));
  size_t elemSize = size_t(comps) * size_t(csize);
  const unsigned char* val =
      fits(acc.sparse.values.bufferView, acc.sparse.values.byteOffset, n * elemSize);
  for (size_t s = 0; s < n; ++s) {
    double target = component(idx + s * size_t(isize), ict, false);
    if (target < 0 || target >= double(acc.count)) {
      fail(path_, name + ": sparse index " + std::to_string(uint64_t(target)) +
                      " out of range (count " + std::to_string(acc.count) + ")");
    }
    for (int c = 0; c < comps; ++c)
      out[size_t(target) * size_t(comps) + size_t(c)] = component(
          val + s * elemSize + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
  }
}

template <typename T>
T GltfReader::load(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

double GltfReader::component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      double v = load<int8_t>(p);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      double v = load<uint8_t>(p);
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      double v = load<int16_t>(p);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      double v = load<uint16_t>(p);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_INT:
      return double(load<int32_t>(p));
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return double(load<uint32_t>(p));
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return double(load<float>(p));
    case TINYGLTF_COMPONENT_TYPE_DOUBLE:
      return load<double>(p);
    default:
      return 0.0;
  }
}

}  // namespace lo::scene_internal::gltf_internal
