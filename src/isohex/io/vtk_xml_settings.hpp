#pragma once
/// \file vtk_xml_settings.hpp
/// \brief The file-wide settings of a VTK XML file, read from `<VTKFile>` and
/// `<AppendedData>`: shared by the readers of the different dataset types (.vtu, .vti).

#include "isohex/io/vtk_xml_data.hpp"
#include "isohex/io/xml_lite.hpp"

#include <string_view>

namespace isohex::io::vtkxml {

/// Checks that the root element is `<VTKFile type="TYPE">` and fills `context` (byte order,
/// header type, zlib compressor, appended data and its encoding). `what` names what this
/// reader reads, for the message when the type differs ("UnstructuredGrid (.vtu) meshes").
/// Throws isohex::Error "FILE: line L (byte B): fault" for unknown or unsupported settings.
void read_settings(const xml::Document& doc, std::string_view type, std::string_view what, Context& context);

}  // namespace isohex::io::vtkxml
