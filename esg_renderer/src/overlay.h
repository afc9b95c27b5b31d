#pragma once
// The ESG's overlay (docs/esg.md): the frame counter, the camera station,
// the mode and the collision / receptacle / acquired / docked indicators,
// drawn into the frame in a 5 x 7 dot font when the control word's OVERLAY
// bit is set.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rms/mesh.h"
#include "rms/word_blocks.h"

namespace rms::esg {

// Draws `text` (A-Z, 0-9, space, - : . / ,; others as blanks) with its top
// left at (x, y), each dot `scale` pixels square, into an RGBA image.
void DrawText(std::uint8_t* rgba, int width, int height, int x, int y, std::string_view text,
              const Rgb& colour, int scale);
void FillRect(std::uint8_t* rgba, int width, int height, int x0, int y0, int x1, int y1, const Rgb& colour);

// camera_names: the stations' names (config order).
void DrawOverlay(std::uint8_t* rgba, int width, int height, const EsgFrameData& frame,
                 const std::vector<std::string>& camera_names);

}  // namespace rms::esg
