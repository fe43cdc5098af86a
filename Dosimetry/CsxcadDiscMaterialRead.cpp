// A corrected CSPropDiscMaterial::ReadDataSet for the CSXCAD of Debian 12 (0.6.2, 2018-12), whose
// discrete materials cannot be read at all with HDF5 1.10: the function takes the HDF5 type as
// `int`, so the 64-bit hid_t of H5T_NATIVE_FLOAT is truncated and never recognised ("ReadDataSet:
// Error, unknown data type"; the mesh is refused and the material silently becomes "Unknown").
// Upstream fixed it in 2026 (CSXCAD 937d700, "fix hid_t truncation bug in ReadDataSet").
//
// libCSXCAD calls ReadDataSet through its PLT, so this definition replaces the library's when
// the shared library built from this file is preloaded (LD_PRELOAD=libReposeCsxcadFix.so, as
// Python/examples/sar_per_posture.py and the tests do) or linked into a program before
// libCSXCAD. It recognises the truncated type by truncating the candidates the same way and
// reads the dataset with the real type, allocating as the caller frees (new T[]).
#include <CSXCAD/CSPropDiscMaterial.h>

#include <hdf5.h>
#include <hdf5_hl.h>

#include <iostream>
#include <vector>

namespace {

template <class T>
void* readAll(hid_t file, const char* name, hid_t type, std::size_t count) {
  T* data = new T[count];
  if (H5LTread_dataset(file, name, type, data) < 0) {
    delete[] data;
    return nullptr;
  }
  return data;
}

}  // namespace

void* CSPropDiscMaterial::ReadDataSet(std::string filename, std::string d_name, int type_id,
                                      int& rank, unsigned int& size, bool debug) {
  rank = -1;
  size = 0;
  enum class Kind { None, Float, Int, UInt8 } kind = Kind::None;
  hid_t type = -1;
  if (type_id == static_cast<int>(H5T_NATIVE_FLOAT)) kind = Kind::Float, type = H5T_NATIVE_FLOAT;
  if (type_id == static_cast<int>(H5T_NATIVE_INT)) kind = Kind::Int, type = H5T_NATIVE_INT;
  if (type_id == static_cast<int>(H5T_NATIVE_UINT8)) kind = Kind::UInt8, type = H5T_NATIVE_UINT8;
  if (kind == Kind::None) {
    std::cerr << "ReadDataSet: Error, unknown data type" << std::endl;
    return nullptr;
  }
  const hid_t file = H5Fopen(filename.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) {
    if (debug) std::cerr << "ReadDataSet: failed to open " << filename << std::endl;
    return nullptr;
  }
  void* data = nullptr;
  if (H5Lexists(file, d_name.c_str(), H5P_DEFAULT) > 0 &&
      H5LTget_dataset_ndims(file, d_name.c_str(), &rank) >= 0 && rank > 0) {
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    H5T_class_t typeClass;
    std::size_t typeSize = 0;
    if (H5LTget_dataset_info(file, d_name.c_str(), dims.data(), &typeClass, &typeSize) >= 0) {
      std::size_t count = 1;
      for (const hsize_t d : dims) count *= static_cast<std::size_t>(d);
      size = static_cast<unsigned int>(count);
      if (kind == Kind::Float) data = readAll<float>(file, d_name.c_str(), type, count);
      if (kind == Kind::Int) data = readAll<int>(file, d_name.c_str(), type, count);
      if (kind == Kind::UInt8) data = readAll<uint8>(file, d_name.c_str(), type, count);
    }
  }
  if (!data && debug) std::cerr << "ReadDataSet: cannot read \"" << d_name << "\"" << std::endl;
  H5Fclose(file);
  return data;
}
