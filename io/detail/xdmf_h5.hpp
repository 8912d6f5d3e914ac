#pragma once
// Internal: the XDMF sidecar writer on a recording that is already open (the recorder's own
// handle). Not installed.
#include <hdf5.h>

#include <string>

#include <jelly/io/h5_recorder.hpp>

namespace jelly {

// Brings /xdmf of the open recording up to date with its frames and returns the sidecar's text,
// which names the recording by the file name of h5_path (the sidecar goes beside it). The file
// must be open for writing; the caller holds h5::library_mutex(). Throws InputError if the file
// is not a jelly recording.
std::string update_xdmf(hid_t file, const std::string& h5_path, const XdmfOptions& options);

}  // namespace jelly
