// Legacy VTK mesh reader: "# vtk DataFile" files with DATASET UNSTRUCTURED_GRID, ASCII or
// BINARY. Cell type 10 (VTK_TETRA) is kept; other cells are checked and ignored.
//
// Layout (vtk-file-formats, "Simple Legacy Formats"):
//   # vtk DataFile Version 3.0        line 1; the version decides the CELLS layout (below)
//   any title                         line 2
//   ASCII | BINARY                    line 3
//   DATASET UNSTRUCTURED_GRID
//   POINTS n float|double             3n values
//   CELLS n size                      up to 4.2: `size` ints, per cell "npts id0 id1 ..."
//   CELLS n+1 m                       5.1 (VTK 9): then "OFFSETS type" n+1 values and
//                                     "CONNECTIVITY type" m values; cell i is
//                                     connectivity[offsets[i] .. offsets[i+1])
//   CELL_TYPES n                      n ints
//   POINT_DATA n / CELL_DATA n        attributes (SCALARS, FIELD, VECTORS, ...): skipped, except
//                                     CELL_DATA's one-component integer arrays, which give the
//                                     tetrahedra's labels (below)
// ASCII values are separated by any white space. BINARY values are big-endian, start right
// after the keyword's line and are followed by a line end; legacy CELLS and CELL_TYPES are
// 32-bit ints. Point indices are 0-based, so the Mesh's nodes are the file's points as they
// are. FIELD and METADATA blocks before the cells are skipped.
//
// Labels (regions by label, issue 19): a one-component array of an integer type in
// CELL_DATA, SCALARS or a FIELD array: the one named "gmsh:physical" (meshio's name for
// Gmsh's physical groups) when there is one, else the first. The data sections never fail
// the mesh, which needs none of them: one this reader cannot read (a type it does not
// know, a truncated block) ends the reading there, and Mesh::labels_from says why there
// are no labels, for the scenario that asks for them.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "host/common/input_error.h"
#include "host/mesh/mesh_formats.h"
#include "host/mesh/text_cursor.h"

namespace sigmafem {

namespace {

constexpr long long kTetraCellType = 10;  // VTK_TETRA
constexpr int kFirstOffsetsVersion = 5;   // VTK 9 writes 5.1: CELLS as OFFSETS + CONNECTIVITY

// A data type name as legacy VTK writes it, and how to decode it in a BINARY file.
struct ValueType {
  enum class Kind { real, signed_integer, unsigned_integer };
  const char* name;
  std::size_t bytes;
  Kind kind;
};

// "long" and "unsigned_long" are left out on purpose: their size in a binary file is the
// writer's sizeof(long), which the file does not record.
constexpr ValueType kValueTypes[] = {
    {"float", 4, ValueType::Kind::real},
    {"double", 8, ValueType::Kind::real},
    {"char", 1, ValueType::Kind::signed_integer},
    {"unsigned_char", 1, ValueType::Kind::unsigned_integer},
    {"short", 2, ValueType::Kind::signed_integer},
    {"unsigned_short", 2, ValueType::Kind::unsigned_integer},
    {"int", 4, ValueType::Kind::signed_integer},
    {"unsigned_int", 4, ValueType::Kind::unsigned_integer},
    {"vtktypeint32", 4, ValueType::Kind::signed_integer},
    {"vtktypeuint32", 4, ValueType::Kind::unsigned_integer},
    {"vtktypeint64", 8, ValueType::Kind::signed_integer},
    {"vtktypeuint64", 8, ValueType::Kind::unsigned_integer},
};
constexpr ValueType kInt32 = {"int", 4, ValueType::Kind::signed_integer};
// COLOR_SCALARS and LOOKUP_TABLE values: floats in ASCII files, bytes in BINARY ones.
constexpr ValueType kUnsignedChar = {"unsigned_char", 1, ValueType::Kind::unsigned_integer};

std::string lower_case(std::string_view text) {
  std::string lower(text);
  for (char& c : lower) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return lower;
}

// The `bytes` bytes at `p` as a big-endian unsigned number.
std::uint64_t big_endian(const char* p, std::size_t bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < bytes; ++i) value = (value << 8) | static_cast<unsigned char>(p[i]);
  return value;
}

// Sign-extends a `bytes`-byte two's complement number.
long long to_signed(std::uint64_t value, std::size_t bytes) {
  if (bytes < 8 && (value >> (8 * bytes - 1)) != 0) value |= ~std::uint64_t{0} << (8 * bytes);
  std::int64_t result = 0;
  std::memcpy(&result, &value, sizeof result);
  return result;
}

class VtkReader {
 public:
  explicit VtkReader(TextCursor& in) : in_(in) {}

  Mesh read() {
    read_header();
    while (!(have_points_ && have_cells_ && have_cell_types_)) {
      const std::string_view token = in_.next_token();
      if (token.empty()) break;
      const std::string keyword = lower_case(token);
      if (keyword == "points") {
        read_points();
      } else if (keyword == "cells") {
        read_cells();
      } else if (keyword == "cell_types") {
        read_cell_types();
      } else if (keyword == "field") {
        skip_field();
      } else if (keyword == "metadata") {
        skip_metadata();
      } else {
        in_.fail("expected POINTS, CELLS or CELL_TYPES, found " + quote_for_message(token));
      }
    }
    if (have_points_ && have_cells_ && have_cell_types_) read_data_sections();
    return finish();
  }

 private:
  void read_header() {
    const std::vector<std::string_view> title_line =
        split_fields(in_.require_line("\"# vtk DataFile Version x.y\""));
    if (title_line.size() < 3 || title_line[0] != "#" || lower_case(title_line[1]) != "vtk") {
      in_.fail("expected \"# vtk DataFile Version x.y\"");
    }
    // Version 1.0 files have no number; anything before 5 uses the classic CELLS layout.
    if (title_line.size() >= 5) {
      const double version = parse_real(title_line.back(), in_, "the VTK file version");
      // Clamped before the cast: a version outside int's range (fuzzing found -8.9e12) is
      // undefined behaviour to convert, and any version below 5 reads the same.
      major_version_ = static_cast<int>(std::clamp(version, 0.0, 100.0));
    }
    in_.require_line("the title line");
    const std::vector<std::string_view> encoding =
        split_fields(in_.require_line("ASCII or BINARY"));
    const std::string name = encoding.size() == 1 ? lower_case(encoding[0]) : std::string();
    if (name != "ascii" && name != "binary") {
      in_.fail("expected ASCII or BINARY on line 3, found " +
               quote_for_message(encoding.empty() ? "" : encoding[0]));
    }
    binary_ = name == "binary";
    if (lower_case(in_.require_token("DATASET")) != "dataset") {
      in_.fail("expected DATASET UNSTRUCTURED_GRID after the header");
    }
    const std::string_view dataset = in_.require_token("the dataset type");
    if (lower_case(dataset) != "unstructured_grid") {
      in_.fail("DATASET " + std::string(dataset) +
               " is not supported: sigmafem needs a volume mesh, DATASET UNSTRUCTURED_GRID "
               "with tetrahedra (cell type 10)");
    }
  }

  void read_points() {
    if (have_points_) in_.fail("a second POINTS block");
    points_line_ = in_.line();
    const long long count = read_count("the number of points");
    const ValueType& type = read_type();
    if (type.kind != ValueType::Kind::real) {
      in_.fail("POINTS must be float or double, found " + std::string(type.name));
    }
    const std::vector<double> xyz = read_reals(3 * count, type, "POINTS coordinates");
    mesh_.nodes.resize(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < mesh_.nodes.size(); ++i) {
      mesh_.nodes[i] = Eigen::Vector3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
    have_points_ = true;
  }

  void read_cells() {
    if (have_cells_) in_.fail("a second CELLS block");
    cells_line_ = in_.line();
    const long long first = read_count("the number of cells");
    const long long second = read_count("the CELLS size");
    if (major_version_ < kFirstOffsetsVersion) {
      // Classic layout: `second` ints, "npts id0 id1 ..." per cell.
      const std::vector<long long> list = read_integers(second, kInt32, "CELLS");
      cell_offsets_.push_back(0);
      std::size_t k = 0;
      for (long long i = 0; i < first; ++i) {
        if (k >= list.size()) {
          in_.fail_at(cells_line_, "CELLS: the list of " + std::to_string(second) +
                                       " values ends before cell " + std::to_string(i));
        }
        const long long points = list[k];
        if (points < 0 || static_cast<unsigned long long>(points) >= list.size() - k) {
          in_.fail_at(cells_line_, "CELLS: cell " + std::to_string(i) + " says it has " +
                                       std::to_string(points) +
                                       " points, more than the list holds");
        }
        cell_points_.insert(cell_points_.end(), list.begin() + static_cast<long>(k + 1),
                            list.begin() + static_cast<long>(k + 1 + points));
        cell_offsets_.push_back(static_cast<long long>(cell_points_.size()));
        k += static_cast<std::size_t>(points) + 1;
      }
      if (k != list.size()) {
        in_.fail_at(cells_line_, "CELLS: the header says " + std::to_string(second) +
                                     " values, the " + std::to_string(first) + " cells use " +
                                     std::to_string(k));
      }
    } else {
      // 5.1: `first` offsets (one more than the cells) and `second` connectivity entries.
      expect_keyword("OFFSETS");
      cell_offsets_ = read_integers(first, read_integer_type(), "OFFSETS");
      expect_keyword("CONNECTIVITY");
      cell_points_ = read_integers(second, read_integer_type(), "CONNECTIVITY");
      if (cell_offsets_.empty() || cell_offsets_.front() != 0 || cell_offsets_.back() != second ||
          !std::is_sorted(cell_offsets_.begin(), cell_offsets_.end())) {
        in_.fail_at(cells_line_, "CELLS: OFFSETS must rise from 0 to the CONNECTIVITY size " +
                                     std::to_string(second));
      }
    }
    have_cells_ = true;
  }

  void read_cell_types() {
    if (have_cell_types_) in_.fail("a second CELL_TYPES block");
    cell_types_line_ = in_.line();
    const long long count = read_count("the number of cell types");
    cell_types_ = read_integers(count, kInt32, "CELL_TYPES");
    have_cell_types_ = true;
  }

  // "FIELD name n" then n arrays "name components tuples type" with their values.
  void skip_field() {
    in_.require_token("the field name");
    const long long arrays = read_count("the number of field arrays");
    for (long long a = 0; a < arrays; ++a) {
      in_.require_token("a field array name");
      const long long components = read_count("the number of components");
      const long long tuples = read_count("the number of tuples");
      const ValueType& type = read_type();
      if (components > 0 && tuples > kMaxMeshCount / components) {
        in_.fail("field array of " + std::to_string(components) + " x " + std::to_string(tuples) +
                 " values is too large");
      }
      if (type.kind == ValueType::Kind::real) {
        read_reals(components * tuples, type, "FIELD values");
      } else {
        read_integers(components * tuples, type, "FIELD values");
      }
    }
  }

  // METADATA (VTK 8+) is text that ends at the first empty line.
  void skip_metadata() {
    in_.finish_line();
    while (const std::optional<std::string_view> line = in_.next_line()) {
      if (split_fields(*line).empty()) return;
    }
  }

  // ---- data sections: the labels -----------------------------------------------------------

  void read_data_sections() {
    try {
      bool cell_data = false;
      long long count = -1;  // values per component in the current section
      while (true) {
        const std::string_view token = in_.next_token();
        if (token.empty()) break;
        const std::string keyword = lower_case(token);
        if (keyword == "point_data" || keyword == "cell_data") {
          cell_data = keyword == "cell_data";
          count = read_count("the number of values");
        } else if (keyword == "metadata") {
          skip_metadata();
        } else if (count < 0) {
          in_.fail("expected POINT_DATA or CELL_DATA, found " + quote_for_message(token));
        } else {
          read_attribute(keyword, count, cell_data);
        }
      }
    } catch (const InputError& error) {
      data_stopped_ = std::string("reading the data sections stopped: ") + error.what();
    }
  }

  // One attribute of a data section of `count` tuples; SCALARS and FIELD arrays of CELL_DATA
  // become label candidates.
  void read_attribute(const std::string& keyword, long long count, bool cell_data) {
    const int line = in_.line();
    if (keyword == "scalars") {
      const std::string name(in_.require_token("the array name"));
      const ValueType& type = read_type();
      long long components = 1;
      TextCursor ahead = in_;  // the component count is optional, on the same line
      const std::string_view next = ahead.next_token();
      if (!next.empty() && ahead.line() == in_.line()) components = read_count("the number of components");
      ahead = in_;  // so is, against the format's text but as VTK's reader allows, LOOKUP_TABLE
      if (lower_case(ahead.next_token()) == "lookup_table") {
        in_.next_token();
        in_.require_token("the lookup table's name");
      }
      read_array(name, line, components, count, type, cell_data);
    } else if (keyword == "field") {
      in_.require_token("the field name");
      const long long arrays = read_count("the number of field arrays");
      for (long long a = 0; a < arrays; ++a) {
        const std::string name(in_.require_token("a field array name"));
        const int array_line = in_.line();
        const long long components = read_count("the number of components");
        const long long tuples = read_count("the number of tuples");
        read_array(name, array_line, components, tuples, read_type(), cell_data);
      }
    } else if (keyword == "vectors" || keyword == "normals" || keyword == "tensors" ||
               keyword == "tensors6" || keyword == "global_ids" || keyword == "pedigree_ids") {
      in_.require_token("the array name");
      const long long components = keyword == "vectors" || keyword == "normals" ? 3
                                   : keyword == "tensors"                     ? 9
                                   : keyword == "tensors6"                    ? 6
                                                                              : 1;
      skip_values(components, count, read_type());
    } else if (keyword == "texture_coordinates") {
      in_.require_token("the array name");
      const long long dimension = read_count("the texture dimension");
      skip_values(dimension, count, read_type());
    } else if (keyword == "color_scalars") {
      in_.require_token("the array name");
      skip_values(read_count("the number of values"), count, kUnsignedChar);
    } else if (keyword == "lookup_table") {
      in_.require_token("the lookup table's name");
      skip_values(4, read_count("the lookup table's size"), kUnsignedChar);
    } else {
      in_.fail("expected a data attribute (SCALARS, FIELD, VECTORS, ...), found " + quote_for_message(keyword));
    }
  }

  // An array of `components` x `tuples` values: a label candidate when it is one integer a
  // cell, else skipped.
  void read_array(const std::string& name, int line, long long components, long long tuples,
                  const ValueType& type, bool cell_data) {
    if (!cell_data || components != 1 || type.kind == ValueType::Kind::real) {
      skip_values(components, tuples, type);
      return;
    }
    std::vector<long long> values = read_integers(tuples, type, "CELL_DATA values");
    if (label_array_.empty() || (name == "gmsh:physical" && label_array_name_ != name)) {
      label_array_ = std::move(values);
      label_array_name_ = name;
      label_array_line_ = line;
    }
  }

  void skip_values(long long components, long long tuples, const ValueType& type) {
    if (components > 0 && tuples > kMaxMeshCount / components) {
      in_.fail("an array of " + std::to_string(components) + " x " + std::to_string(tuples) +
               " values is too large");
    }
    const long long count = components * tuples;
    if (binary_) {
      read_block(count, type, "data values");
    } else {
      for (long long i = 0; i < count; ++i) in_.require_token("data values");
    }
  }

  // ---- values -----------------------------------------------------------------------------

  long long read_count(const char* what) {
    return parse_integer_in(in_.require_token(what), 0, kMaxMeshCount, in_, what);
  }

  const ValueType& read_type() {
    const std::string_view token = in_.require_token("a data type");
    const std::string name = lower_case(token);
    for (const ValueType& type : kValueTypes) {
      if (name == type.name) return type;
    }
    in_.fail("data type " + quote_for_message(token) +
             " is not supported (expected float, double, int, vtktypeint64, ...)");
  }

  const ValueType& read_integer_type() {
    const ValueType& type = read_type();
    if (type.kind == ValueType::Kind::real) {
      in_.fail("expected an integer data type, found " + std::string(type.name));
    }
    return type;
  }

  void expect_keyword(const char* keyword) {
    const std::string_view token = in_.require_token(keyword);
    if (lower_case(token) != lower_case(keyword)) {
      in_.fail(std::string("expected ") + keyword + ", found " + quote_for_message(token));
    }
  }

  // The raw big-endian block of `count` values of `type` (BINARY files only).
  std::string_view read_block(long long count, const ValueType& type, const char* what) {
    in_.finish_line();
    const auto n = static_cast<std::size_t>(count);
    if (n > in_.remaining() / type.bytes) {
      in_.fail_at_end(std::to_string(count) + " " + type.name + " values of " + what);
    }
    return in_.read_bytes(n * type.bytes, what);
  }

  std::vector<double> read_reals(long long count, const ValueType& type, const char* what) {
    std::vector<double> values;
    if (!binary_) {
      // Each ASCII value takes at least two bytes ("0 "): a corrupt count reserves no more.
      values.reserve(std::min(static_cast<std::size_t>(count), in_.remaining() / 2 + 1));
      for (long long i = 0; i < count; ++i) {
        values.push_back(parse_real(in_.require_token(what), in_, what));
      }
      return values;
    }
    const std::string_view block = read_block(count, type, what);
    values.reserve(block.size() / type.bytes);
    for (std::size_t at = 0; at < block.size(); at += type.bytes) {
      const std::uint64_t bits = big_endian(block.data() + at, type.bytes);
      double value = 0.0;
      if (type.bytes == 4) {
        const auto bits32 = static_cast<std::uint32_t>(bits);
        float single = 0.0f;
        std::memcpy(&single, &bits32, sizeof single);
        value = single;
      } else {
        std::memcpy(&value, &bits, sizeof value);
      }
      if (!std::isfinite(value)) {
        in_.fail(std::string(what) + ": value " + std::to_string(at / type.bytes) +
                 " is not a finite number");
      }
      values.push_back(value);
    }
    return values;
  }

  std::vector<long long> read_integers(long long count, const ValueType& type, const char* what) {
    std::vector<long long> values;
    if (!binary_) {
      // Each ASCII value takes at least two bytes ("0 "): a corrupt count reserves no more.
      values.reserve(std::min(static_cast<std::size_t>(count), in_.remaining() / 2 + 1));
      for (long long i = 0; i < count; ++i) {
        values.push_back(parse_integer(in_.require_token(what), in_, what));
      }
      return values;
    }
    const std::string_view block = read_block(count, type, what);
    values.reserve(block.size() / type.bytes);
    for (std::size_t at = 0; at < block.size(); at += type.bytes) {
      const std::uint64_t bits = big_endian(block.data() + at, type.bytes);
      // An unsigned 64-bit value above LLONG_MAX turns negative here and fails as an index.
      values.push_back(type.kind == ValueType::Kind::signed_integer ? to_signed(bits, type.bytes)
                                                                    : to_signed(bits, 8));
    }
    return values;
  }

  // ---- cells to tetrahedra ----------------------------------------------------------------

  Mesh finish() {
    const std::string& source = in_.source();
    if (!have_points_) throw_mesh_error(source, "no POINTS block");
    if (!have_cells_) throw_mesh_error(source, "no CELLS block");
    if (!have_cell_types_) throw_mesh_error(source, "no CELL_TYPES block");
    const auto cells = static_cast<long long>(cell_offsets_.size()) - 1;
    if (static_cast<long long>(cell_types_.size()) != cells) {
      in_.fail_at(cell_types_line_, "CELL_TYPES lists " + std::to_string(cell_types_.size()) +
                                        " types for " + std::to_string(cells) + " cells");
    }
    const long long points = mesh_.node_count();
    long long other_cells = 0;
    for (long long i = 0; i < cells; ++i) {
      const auto begin = static_cast<std::size_t>(cell_offsets_[static_cast<std::size_t>(i)]);
      const auto end = static_cast<std::size_t>(cell_offsets_[static_cast<std::size_t>(i) + 1]);
      for (std::size_t k = begin; k < end; ++k) {
        if (cell_points_[k] < 0 || cell_points_[k] >= points) {
          in_.fail_at(cells_line_, "cell " + std::to_string(i) + " refers to point " +
                                       std::to_string(cell_points_[k]) + ", but POINTS (line " +
                                       std::to_string(points_line_) + ") defines " +
                                       std::to_string(points) + " points");
        }
      }
      if (cell_types_[static_cast<std::size_t>(i)] != kTetraCellType) {
        ++other_cells;
        continue;
      }
      if (end - begin != 4) {
        in_.fail_at(cells_line_, "cell " + std::to_string(i) +
                                     " is a tetrahedron (type 10) but has " +
                                     std::to_string(end - begin) + " points, expected 4");
      }
      const long long* p = &cell_points_[begin];
      mesh_.tetrahedra.push_back({static_cast<int>(p[0]), static_cast<int>(p[1]),
                                  static_cast<int>(p[2]), static_cast<int>(p[3])});
    }
    if (mesh_.tetrahedra.empty()) {
      throw_mesh_error(source, "no tetrahedra (VTK cell type 10): the file has " +
                                   std::to_string(other_cells) +
                                   " cells of other types; sigmafem needs a volume mesh");
    }
    keep_labels(cells);
    return std::move(mesh_);
  }

  // The label array's values of the tetrahedra, or in labels_from why there are none.
  void keep_labels(long long cells) {
    if (label_array_.empty()) {
      mesh_.labels_from = !data_stopped_.empty() ? data_stopped_ : "no one-component integer array in CELL_DATA";
      return;
    }
    const std::string array = "CELL_DATA array \"" + label_array_name_ + "\" (line " + std::to_string(label_array_line_) + ")";
    if (static_cast<long long>(label_array_.size()) != cells) {
      mesh_.labels_from = array + " has " + std::to_string(label_array_.size()) + " values for " +
                          std::to_string(cells) + " cells";
      return;
    }
    std::vector<int> labels;
    for (long long i = 0; i < cells; ++i) {
      if (cell_types_[static_cast<std::size_t>(i)] != kTetraCellType) continue;
      const long long label = label_array_[static_cast<std::size_t>(i)];
      if (label < INT_MIN || label > INT_MAX) {
        mesh_.labels_from = array + ": cell " + std::to_string(i) + "'s value " + std::to_string(label) + " is not an int";
        return;
      }
      labels.push_back(static_cast<int>(label));
    }
    mesh_.labels = std::move(labels);
    mesh_.labels_from = array;
  }

  TextCursor& in_;
  bool binary_ = false;
  int major_version_ = 3;
  Mesh mesh_;
  // All cells as one list: cell i's points are cell_points_[cell_offsets_[i] .. [i + 1]).
  std::vector<long long> cell_offsets_;
  std::vector<long long> cell_points_;
  std::vector<long long> cell_types_;
  bool have_points_ = false;
  bool have_cells_ = false;
  bool have_cell_types_ = false;
  int points_line_ = 0;
  int cells_line_ = 0;
  int cell_types_line_ = 0;
  // The CELL_DATA array chosen for the labels, one value a cell, and why reading stopped.
  std::vector<long long> label_array_;
  std::string label_array_name_;
  int label_array_line_ = 0;
  std::string data_stopped_;
};

}  // namespace

Mesh read_vtk(std::string_view text, const std::string& source) {
  TextCursor in(text, source);
  return VtkReader(in).read();
}

}  // namespace sigmafem
