#pragma once
/// \file
/// Velocitek VTK logs (ProStart, Shift; the vendor's public protobuf description `vtk.proto`):
/// records, each a little-endian u16 length and that many bytes of a protobuf `Record`, a oneof of
/// Trackpoint (1), TimerEvent (2), ButtonEvent (16), HardwareDescription (17) and
/// MagneticDeclination (18).
/// - Trackpoint: seconds + centiseconds UTC, lat/lon in 1e-7 deg (sint32), SOG in 0.1 kn, COG in
///   degrees, and the device's orientation as a quaternion x 1e3 (q1 the scalar part) relative to
///   magnetic north, in a z-up frame: heel is its roll, pitch its negated pitch, the magnetic
///   heading its negated yaw (as the vendor's own converter reads it). The heading becomes true
///   with the file's declination record, else ImportOptions::declination_deg, else it is left out.
/// - Timer and button events become ImportEvents; the hardware description names the device.
///
/// The protobuf wire format is decoded here by hand (varints, zigzag, length-delimited fields,
/// unknown fields skipped by wire type): no generated code to keep in step with a schema we do
/// not own, no protobuf library to build against, and one record (at most 64 KB) in memory.
/// A record cut by the end of the file, or one that does not decode, ends the parse: what came
/// before is kept (kPartial, with the byte offset).

#include "record.hpp"

namespace telltale::shore::import {

[[nodiscard]] ParseResult parse_vtk(std::istream& in, const ImportOptions& options,
                                    ImportSink& sink);

/// The device's serial number from a HardwareDescription record among the whole records at the
/// start of `data` (the head of a file), for a default boat id; nullopt when there is none.
[[nodiscard]] std::optional<std::int64_t> vtk_serial_number(std::string_view data);

/// True if `data` holds a whole VTK record at its start whose protobuf decodes (for detection).
[[nodiscard]] bool looks_like_vtk(std::string_view data);

}  // namespace telltale::shore::import
