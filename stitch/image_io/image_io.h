// Reading and writing grey-value images (TIFF, PNG, JPEG, ... as OpenCV's imgcodecs reads them,
// through the module image_codecs.h loads on first use).
// Colour images are converted to grey; 8- and 16-bit depths keep their digital numbers. EXIF
// orientation is ignored: the stored pixel array is what the sensor wrote, and that is what the
// camera file's sub-image formats describe.
#pragma once

#include "calib/camera/subimage_mapping.h"
#include "stitch/image_io/gray_image.h"

#include <string>

namespace aerocal::stitch {

/// Reads an image as grey values. InputError "PATH: ..." when the file is missing or unreadable.
GrayImage ReadGrayImage(const std::string& path);

/// Reads the image of one sub-image and checks its format against the camera file:
/// InputError "PATH: image is W x H px, but sub-image ID of the camera file is W' x H' px".
GrayImage ReadSubimage(const std::string& path, const calib::SubimageMapping& subimage);

/// Writes grey values rounded and clamped to 8 bit (`bits` = 8) or 16 bit (`bits` = 16), in the
/// format the extension names (.tif, .png). Throws Error when the file cannot be written.
void WriteGrayImage(const std::string& path, const GrayImage& image, int bits = 8);

}  // namespace aerocal::stitch
