#include <jelly/io/xdmf.hpp>

#include <fstream>
#include <sstream>

#include <jelly/core/errors.hpp>
#include <jelly/io/detail/h5.hpp>
#include <jelly/io/h5_recorder.hpp>

namespace jelly {

namespace {

// A HyperSlab DataItem selecting frame `frame` ([1][rows][3]) of the dataset [T][rows][3]:
// start (frame, 0, 0), stride (1, 1, 1), count (1, rows, 3).
void frame_slab(std::ostream& out, const XdmfLayout& layout, size_t frame, int rows,
                const char* dataset) {
  out << "          <DataItem ItemType=\"HyperSlab\" Dimensions=\"1 " << rows << " 3\">\n"
      << "            <DataItem Dimensions=\"3 3\" Format=\"XML\">" << frame << " 0 0 1 1 1 1 "
      << rows << " 3</DataItem>\n"
      << "            <DataItem Dimensions=\"" << layout.times.size() << ' ' << rows
      << " 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << layout.h5_file << ':'
      << dataset << "</DataItem>\n"
      << "          </DataItem>\n";
}

}  // namespace

std::string xdmf_text(const XdmfLayout& layout) {
  std::ostringstream out;
  out.precision(17);
  const int n = layout.num_particles, m = layout.num_springs;
  out << "<?xml version=\"1.0\" ?>\n"
      << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      << "<Xdmf Version=\"2.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
      << "  <Domain>\n"
      << "    <Grid Name=\"jelly\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (size_t f = 0; f < layout.times.size(); ++f) {
    out << "      <Grid Name=\"frame_" << f << "\" GridType=\"Uniform\">\n"
        << "        <Time Value=\"" << layout.times[f] << "\"/>\n"
        << "        <Topology TopologyType=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\""
        << m << "\">\n"
        << "          <DataItem Dimensions=\"" << m
        << " 2\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << layout.h5_file
        << ":/connectivity/springs</DataItem>\n"
        << "        </Topology>\n"
        << "        <Geometry GeometryType=\"XYZ\">\n";
    frame_slab(out, layout, f, n, "/particles/jelly/position/value");
    out << "        </Geometry>\n"
        << "        <Attribute Name=\"velocity\" AttributeType=\"Vector\" Center=\"Node\">\n";
    frame_slab(out, layout, f, n, "/particles/jelly/velocity/value");
    out << "        </Attribute>\n"
        << "        <Attribute Name=\"mass\" AttributeType=\"Scalar\" Center=\"Node\">\n"
        << "          <DataItem Dimensions=\"" << n
        << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">" << layout.h5_file
        << ":/particles/jelly/mass</DataItem>\n"
        << "        </Attribute>\n"
        << "        <Attribute Name=\"spring_type\" AttributeType=\"Scalar\" Center=\"Cell\">\n"
        << "          <DataItem Dimensions=\"" << m
        << "\" NumberType=\"Int\" Precision=\"4\" Format=\"HDF\">" << layout.h5_file
        << ":/connectivity/type</DataItem>\n"
        << "        </Attribute>\n"
        << "      </Grid>\n";
  }
  out << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return out.str();
}

void write_xdmf(const std::string& xdmf_path, const XdmfLayout& layout) {
  std::ofstream file(xdmf_path);
  if (!file) throw InputError("cannot write XDMF file '" + xdmf_path + "'");
  file << xdmf_text(layout);
  if (!file) throw InputError("cannot write XDMF file '" + xdmf_path + "'");
}

void write_xdmf_for_recording(const std::string& h5_path) {
  XdmfLayout layout;
  {
    std::lock_guard<std::recursive_mutex> lock(h5::library_mutex());
    h5::QuietErrors quiet;
    h5::Handle file = h5::open_file(h5_path);
    try {
      layout.times = h5::read_doubles(file.get(), "/particles/jelly/position/time");
      h5::Handle mass = h5::open_dataset(file.get(), "/particles/jelly/mass");
      layout.num_particles = static_cast<int>(h5::dataset_dims(mass.get()).at(0));
      h5::Handle springs = h5::open_dataset(file.get(), "/connectivity/springs");
      layout.num_springs = static_cast<int>(h5::dataset_dims(springs.get()).at(0));
    } catch (const std::exception& e) {
      throw InputError("'" + h5_path + "' is not a jelly recording: " + e.what());
    }
  }
  const size_t slash = h5_path.find_last_of('/');
  layout.h5_file = slash == std::string::npos ? h5_path : h5_path.substr(slash + 1);
  write_xdmf(xdmf_path_for(h5_path), layout);
}

}  // namespace jelly
