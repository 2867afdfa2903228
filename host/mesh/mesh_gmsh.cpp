// Gmsh ASCII mesh reader: formats 1.0, 2.x (2.2 and the identical 2.0, 2.1) and 4.1.
//
// What the three formats have in common, and what this reader relies on:
//   - the file is a sequence of sections "$Name ... $EndName"; only the nodes and elements
//     sections are read (and 4.1's $Entities, for the volumes' physical groups), every other
//     one ($PhysicalNames, $Periodic, $NodeData...) is skipped whole;
//   - each tetrahedron keeps its physical group as its label (Mesh::labels; 0 without one):
//     1.0's reg-phys, 2.x's first tag, 4.1's volume entity's first physical tag;
//   - nodes carry ids (tags) that need not be 1..n nor contiguous (liver2.msh uses 2..1393),
//     so elements are mapped by id; a node's index in the Mesh is its position in the file;
//   - one node or element per line, as Gmsh and meshio write them. The reader is line based
//     so that every error names its line; it does not accept a node split over two lines.
//
// Layouts (one line each, `...` repeats):
//   1.0  $NOD / n / id x y z ... / $ENDNOD
//        $ELM / n / id type reg-phys reg-elem n-nodes node-ids... / $ENDELM
//   2.x  $MeshFormat / version file-type data-size / $EndMeshFormat
//        $Nodes / n / id x y z ... / $EndNodes
//        $Elements / n / id type n-tags tags... node-ids... / $EndElements
//   4.1  $Entities / n-points n-curves n-surfaces n-volumes / a line per entity; a volume's:
//          tag min-x min-y min-z max-x max-y max-z n-physical physical-tags... n-surfaces ...
//        $Nodes / n-blocks n-nodes min-tag max-tag
//          per block: entity-dim entity-tag parametric n / n tag lines / n lines "x y z [u v w]"
//        $Elements / n-blocks n-elements min-tag max-tag
//          per block: entity-dim entity-tag type n / n lines "tag node-ids..."
// Element type 4 is the 4-node tetrahedron; other types are checked (their node ids must
// exist) and then ignored. Binary Gmsh files (file-type 1) are refused with a clear message.
#include <climits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "host/mesh/mesh_formats.h"
#include "host/mesh/text_cursor.h"

namespace sigmafem {

namespace {

constexpr long long kTetrahedronType = 4;  // Gmsh element type of the 4-node tetrahedron

enum class GmshVersion { v1, v2, v41 };

class GmshReader {
 public:
  explicit GmshReader(TextCursor& in) : in_(in) {}

  Mesh read() {
    const std::optional<std::string_view> first = in_.next_nonblank_line();
    const std::vector<std::string_view> header = split_fields(first.value_or(""));
    if (!header.empty() && header[0] == "$NOD") {
      version_ = GmshVersion::v1;
      read_section("$NOD");
    } else if (!header.empty() && header[0] == "$MeshFormat") {
      read_mesh_format();
    } else {
      in_.fail("expected $MeshFormat or $NOD (a Gmsh file), found " +
               quote_for_message(first.value_or("")));
    }
    while (const std::optional<std::string_view> line = in_.next_nonblank_line()) {
      const std::vector<std::string_view> fields = split_fields(*line);
      if (fields[0].front() != '$') {
        in_.fail("expected a section header ($Name), found " + quote_for_message(*line));
      }
      read_section(fields[0]);
    }
    return finish();
  }

 private:
  // ---- sections -------------------------------------------------------------------------

  void read_mesh_format() {
    const std::vector<std::string_view> fields =
        split_fields(in_.require_line("the format line \"version file-type data-size\""));
    if (fields.size() != 3) {
      in_.fail("expected \"version file-type data-size\" (e.g. \"4.1 0 8\"), found " +
               std::to_string(fields.size()) + " fields");
    }
    const double version = parse_real(fields[0], in_, "the Gmsh format version");
    if (version >= 2.0 && version < 3.0) {
      version_ = GmshVersion::v2;
    } else if (fields[0] == "4.1") {
      version_ = GmshVersion::v41;
    } else {
      in_.fail("Gmsh format version " + std::string(fields[0]) +
               " is not supported (sigmafem reads ASCII 1.0, 2.2 and 4.1); re-export the mesh, "
               "e.g. gmsh -3 -format msh41");
    }
    if (parse_integer(fields[1], in_, "the file type (0 for ASCII)") != 0) {
      in_.fail("binary Gmsh files are not supported; re-export as ASCII (gmsh -bin 0)");
    }
    expect_end("$EndMeshFormat", "$MeshFormat");
  }

  void read_section(std::string_view name) {
    const bool v1 = version_ == GmshVersion::v1;
    if (name == (v1 ? "$NOD" : "$Nodes")) {
      if (have_nodes_) in_.fail("a second " + std::string(name) + " section");
      have_nodes_ = true;
      if (version_ == GmshVersion::v41) {
        read_nodes_v41();
      } else {
        read_nodes_v1_v2();
      }
      expect_end(v1 ? "$ENDNOD" : "$EndNodes", name);
    } else if (name == (v1 ? "$ELM" : "$Elements")) {
      if (!have_nodes_) in_.fail(std::string(name) + " comes before the nodes section");
      if (have_elements_) in_.fail("a second " + std::string(name) + " section");
      have_elements_ = true;
      if (version_ == GmshVersion::v41) {
        read_elements_v41();
      } else {
        read_elements_v1_v2();
      }
      expect_end(v1 ? "$ENDELM" : "$EndElements", name);
    } else if (name == "$Entities" && version_ == GmshVersion::v41) {
      read_entities_v41();
      expect_end("$EndEntities", name);
    } else {
      skip_section(name);
    }
  }

  // The volumes' first physical tags (the labels of their elements); points, curves and
  // surfaces are skipped a line each.
  void read_entities_v41() {
    const std::vector<std::string_view> counts = next_fields("\"n-points n-curves n-surfaces n-volumes\"");
    if (counts.size() != 4)
      in_.fail("expected \"n-points n-curves n-surfaces n-volumes\", found " + std::to_string(counts.size()) + " fields");
    long long lower = 0;
    for (int k = 0; k < 3; ++k) lower += parse_integer_in(counts[k], 0, kMaxMeshCount, in_, "an entity count");
    const long long volumes = parse_integer_in(counts[3], 0, kMaxMeshCount, in_, "the volume count");
    for (long long i = 0; i < lower; ++i) in_.require_line("an entity line");
    for (long long i = 0; i < volumes; ++i) {
      const std::vector<std::string_view> fields = next_fields("a volume entity line");
      if (fields.size() < 8)
        in_.fail("expected a volume entity \"tag min-x min-y min-z max-x max-y max-z n-physical ...\", found " +
                 std::to_string(fields.size()) + " fields");
      const long long tag = parse_integer(fields[0], in_, "a volume tag");
      const long long physical = parse_integer_in(fields[7], 0, kMaxMeshCount, in_, "the physical tag count");
      volume_label_[tag] = physical > 0 && fields.size() > 8 ? label_of(fields[8]) : 0;
    }
  }

  int label_of(std::string_view field) {
    return static_cast<int>(parse_integer_in(field, -kMaxMeshCount, kMaxMeshCount, in_, "a physical tag"));
  }

  // A section we do not need: skip to its "$End<Name>" (Gmsh 1.0 writes "$END<NAME>").
  void skip_section(std::string_view name) {
    const int opened = in_.line();
    const std::string end = "$End" + std::string(name.substr(1));
    while (const std::optional<std::string_view> line = in_.next_line()) {
      const std::vector<std::string_view> fields = split_fields(*line);
      if (!fields.empty() && equal_ignoring_case(fields[0], end)) return;
    }
    in_.fail_at_end(end + " to close " + std::string(name) + " (opened on line " +
                    std::to_string(opened) + ")");
  }

  // After the count of items was read, the next line must close the section: this also
  // catches a count smaller than the real number of lines.
  void expect_end(const std::string& end, std::string_view name) {
    const std::string_view line = in_.require_line(end + " to close " + std::string(name));
    const std::vector<std::string_view> fields = split_fields(line);
    if (fields.size() != 1 || fields[0] != end) {
      in_.fail("expected " + end + " to close " + std::string(name) + ", found " +
               quote_for_message(line));
    }
  }

  // ---- nodes ------------------------------------------------------------------------------

  void read_nodes_v1_v2() {
    const long long count = read_count_line("the number of nodes");
    for (long long i = 0; i < count; ++i) {
      const std::vector<std::string_view> fields = next_fields("node line \"id x y z\"");
      if (fields.size() != 4) {
        in_.fail("expected a node line \"id x y z\", found " + std::to_string(fields.size()) +
                 " fields");
      }
      add_node_id(parse_integer(fields[0], in_, "a node id"));
      mesh_.nodes.push_back(parse_point(fields[1], fields[2], fields[3]));
    }
  }

  void read_nodes_v41() {
    const std::vector<std::string_view> header =
        next_fields("\"n-blocks n-nodes min-tag max-tag\"");
    if (header.size() != 4) {
      in_.fail("expected \"n-blocks n-nodes min-tag max-tag\", found " +
               std::to_string(header.size()) + " fields");
    }
    const long long blocks = parse_integer_in(header[0], 0, kMaxMeshCount, in_, "the block count");
    const long long total = parse_integer_in(header[1], 0, kMaxMeshCount, in_, "the node count");
    long long read = 0;
    for (long long b = 0; b < blocks; ++b) {
      const std::vector<std::string_view> block =
          next_fields("node block \"entity-dim entity-tag parametric n\"");
      if (block.size() != 4) {
        in_.fail("expected a node block header \"entity-dim entity-tag parametric n\", found " +
                 std::to_string(block.size()) + " fields");
      }
      const long long dim = parse_integer_in(block[0], 0, 3, in_, "the entity dimension");
      const long long parametric = parse_integer_in(block[2], 0, 1, in_, "parametric (0 or 1)");
      const long long count =
          parse_integer_in(block[3], 0, total - read, in_, "the block's node count");
      // Parametric nodes add their (u, v, w) on the entity, one per dimension; unused here.
      const std::size_t fields_per_point = 3 + static_cast<std::size_t>(parametric * dim);
      for (long long i = 0; i < count; ++i) {
        const std::vector<std::string_view> tag = next_fields("a node tag");
        if (tag.size() != 1) {
          in_.fail("expected one node tag, found " + std::to_string(tag.size()) + " fields");
        }
        add_node_id(parse_integer(tag[0], in_, "a node tag"));
      }
      for (long long i = 0; i < count; ++i) {
        const std::vector<std::string_view> point = next_fields("node coordinates \"x y z\"");
        if (point.size() != fields_per_point) {
          in_.fail("expected " + std::to_string(fields_per_point) +
                   " coordinates for a node of this block, found " + std::to_string(point.size()) +
                   " fields");
        }
        mesh_.nodes.push_back(parse_point(point[0], point[1], point[2]));
      }
      read += count;
    }
    if (read != total) {
      in_.fail("the node blocks hold " + std::to_string(read) + " nodes, the header said " +
               std::to_string(total));
    }
  }

  // ---- elements ---------------------------------------------------------------------------

  void read_elements_v1_v2() {
    const bool v1 = version_ == GmshVersion::v1;
    const long long count = read_count_line("the number of elements");
    for (long long i = 0; i < count; ++i) {
      const std::vector<std::string_view> fields = next_fields("an element line");
      // 1.0: id type reg-phys reg-elem n-nodes nodes...; 2.x: id type n-tags tags... nodes...
      const std::size_t fixed = v1 ? 5 : 3;
      if (fields.size() < fixed) {
        in_.fail(std::string("expected an element line \"") +
                 (v1 ? "id type reg-phys reg-elem n-nodes node-ids..."
                     : "id type n-tags tags... node-ids...") +
                 "\", found " + std::to_string(fields.size()) + " fields");
      }
      const long long id = parse_integer(fields[0], in_, "an element id");
      const long long type = parse_integer(fields[1], in_, "an element type");
      std::size_t first_node = 0;
      int label = 0;
      if (v1) {
        label = label_of(fields[2]);
        const long long n = parse_integer_in(fields[4], 0, kMaxMeshCount, in_, "the node count");
        if (fields.size() != fixed + static_cast<std::size_t>(n)) {
          in_.fail("element " + std::to_string(id) + " says it has " + std::to_string(n) +
                   " nodes, the line lists " + std::to_string(fields.size() - fixed));
        }
        first_node = fixed;
      } else {
        const long long tags = parse_integer_in(fields[2], 0, kMaxMeshCount, in_, "the tag count");
        if (fields.size() < fixed + static_cast<std::size_t>(tags)) {
          in_.fail("element " + std::to_string(id) + " says it has " + std::to_string(tags) +
                   " tags, the line is shorter");
        }
        first_node = fixed + static_cast<std::size_t>(tags);
        if (tags > 0) label = label_of(fields[3]);
      }
      add_element(id, type, fields, first_node, label);
    }
  }

  void read_elements_v41() {
    const std::vector<std::string_view> header =
        next_fields("\"n-blocks n-elements min-tag max-tag\"");
    if (header.size() != 4) {
      in_.fail("expected \"n-blocks n-elements min-tag max-tag\", found " +
               std::to_string(header.size()) + " fields");
    }
    const long long blocks = parse_integer_in(header[0], 0, kMaxMeshCount, in_, "the block count");
    const long long total = parse_integer_in(header[1], 0, kMaxMeshCount, in_, "the element count");
    long long read = 0;
    for (long long b = 0; b < blocks; ++b) {
      const std::vector<std::string_view> block =
          next_fields("element block \"entity-dim entity-tag type n\"");
      if (block.size() != 4) {
        in_.fail("expected an element block header \"entity-dim entity-tag type n\", found " +
                 std::to_string(block.size()) + " fields");
      }
      const long long type = parse_integer(block[2], in_, "an element type");
      const auto volume = volume_label_.find(parse_integer(block[1], in_, "an entity tag"));
      const int label = volume == volume_label_.end() ? 0 : volume->second;
      const long long count =
          parse_integer_in(block[3], 0, total - read, in_, "the block's element count");
      for (long long i = 0; i < count; ++i) {
        const std::vector<std::string_view> fields = next_fields("an element line");
        if (fields.size() < 2) {
          in_.fail("expected an element line \"tag node-tags...\", found " +
                   std::to_string(fields.size()) + " fields");
        }
        add_element(parse_integer(fields[0], in_, "an element tag"), type, fields, 1, label);
      }
      read += count;
    }
    if (read != total) {
      in_.fail("the element blocks hold " + std::to_string(read) + " elements, the header said " +
               std::to_string(total));
    }
  }

  // Checks that every node id of the element exists (whatever its type: a triangle naming a
  // missing node means the file is broken), keeps tetrahedra, counts the rest.
  void add_element(long long id, long long type, const std::vector<std::string_view>& fields,
                   std::size_t first_node, int label) {
    std::vector<int> nodes;
    nodes.reserve(fields.size() - first_node);
    for (std::size_t k = first_node; k < fields.size(); ++k) {
      const long long node_id = parse_integer(fields[k], in_, "a node id");
      const auto found = node_index_.find(node_id);
      if (found == node_index_.end()) {
        in_.fail("element " + std::to_string(id) + " refers to node " + std::to_string(node_id) +
                 ", which the file does not define");
      }
      nodes.push_back(found->second);
    }
    if (type != kTetrahedronType) {
      ++other_elements_;
      return;
    }
    if (nodes.size() != 4) {
      in_.fail("element " + std::to_string(id) + " is a tetrahedron (type 4) but has " +
               std::to_string(nodes.size()) + " nodes, expected 4");
    }
    if (mesh_.tetrahedra.size() >= static_cast<std::size_t>(kMaxMeshCount)) {
      in_.fail("more than " + std::to_string(kMaxMeshCount) + " tetrahedra");
    }
    mesh_.tetrahedra.push_back({nodes[0], nodes[1], nodes[2], nodes[3]});
    mesh_.labels.push_back(label);
  }

  // ---- helpers ----------------------------------------------------------------------------

  std::vector<std::string_view> next_fields(const std::string& expected) {
    return split_fields(in_.require_line(expected));
  }

  long long read_count_line(const char* what) {
    const std::vector<std::string_view> fields = next_fields(what);
    if (fields.size() != 1) {
      in_.fail(std::string("expected ") + what + " alone on its line, found " +
               std::to_string(fields.size()) + " fields");
    }
    return parse_integer_in(fields[0], 0, kMaxMeshCount, in_, what);
  }

  // The coordinates follow (2.x: on the same line; 4.1: after the block's tags).
  void add_node_id(long long id) {
    if (node_index_.size() >= static_cast<std::size_t>(kMaxMeshCount)) {
      in_.fail("more than " + std::to_string(kMaxMeshCount) + " nodes");
    }
    const int index = static_cast<int>(node_index_.size());
    if (!node_index_.emplace(id, index).second) {
      in_.fail("node " + std::to_string(id) + " is defined twice");
    }
  }

  Eigen::Vector3d parse_point(std::string_view x, std::string_view y, std::string_view z) {
    return {parse_real(x, in_, "an x coordinate"), parse_real(y, in_, "a y coordinate"),
            parse_real(z, in_, "a z coordinate")};
  }

  static bool equal_ignoring_case(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
      if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
  }

  Mesh finish() {
    const bool v1 = version_ == GmshVersion::v1;
    if (!have_nodes_) throw_mesh_error(in_.source(), v1 ? "no $NOD section" : "no $Nodes section");
    if (!have_elements_) {
      throw_mesh_error(in_.source(), v1 ? "no $ELM section" : "no $Elements section");
    }
    if (mesh_.tetrahedra.empty()) {
      throw_mesh_error(in_.source(),
                       "no tetrahedra (Gmsh element type 4): the file has " +
                           std::to_string(other_elements_) +
                           " elements of other types; sigmafem needs a volume mesh (gmsh -3)");
    }
    mesh_.labels_from = "physical groups";
    return std::move(mesh_);
  }

  TextCursor& in_;
  GmshVersion version_ = GmshVersion::v2;
  Mesh mesh_;
  std::unordered_map<long long, int> node_index_;  // file id -> 0-based index in file order
  std::unordered_map<long long, int> volume_label_;  // 4.1: volume entity tag -> its first physical tag
  bool have_nodes_ = false;
  bool have_elements_ = false;
  long long other_elements_ = 0;
};

}  // namespace

Mesh read_gmsh(std::string_view text, const std::string& source) {
  TextCursor in(text, source);
  return GmshReader(in).read();
}

}  // namespace sigmafem
