// The importers: the first byte chooses COLMAP text (cameras / images / points3D separated by
// "\n%%\n"), the DBAT camera XML, DBAT marks (with a fixed camera, images and EO) or an ODM
// gcp_list; each result goes through the block check the `import` command applies.
#include "calib/camera/camera_io.h"
#include "calib/core/yaml_util.h"
#include "tests/fuzz/fuzz_support.h"
#include "triangulation/import/colmap_import.h"
#include "triangulation/import/dbat_import.h"
#include "triangulation/import/odm_gcp_import.h"
#include "triangulation/import/write_project.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace aerocal;
  using namespace aerocal::triangulation;
  if (size < 1) return 0;
  const int kind = data[0] % 4;
  ++data;
  --size;
  const std::string text(reinterpret_cast<const char*>(data), size);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    if (kind == 0) {
      const auto parts = fuzz::Parts(data, size, 3);
      std::filesystem::create_directories(fuzz::ScratchDir() + "/colmap");
      fuzz::WriteScratch("colmap/cameras.txt", parts[0]);
      fuzz::WriteScratch("colmap/images.txt", parts[1]);
      fuzz::WriteScratch("colmap/points3D.txt", parts[2]);
      ColmapImportOptions o;
      o.folder = fuzz::ScratchDir() + "/colmap";
      (void)UsableImportedBlock(ImportColmapModel(o).project, "images.txt");
    } else if (kind == 1) {
      (void)ReadDbatCamera(fuzz::WriteScratch("camera.xml", text));
    } else if (kind == 2) {
      DbatImportOptions o;
      o.camera_xml = fuzz::WriteScratch(
          "dbat.xml",
          "<document><cameras><camera><sensor>auto,24</sensor><image>6000,4000</image>"
          "<cc>35</cc></camera></cameras></document>\n");
      o.images = fuzz::WriteScratch("images.txt", "1, a.jpg\n2, b.jpg\n");
      o.initial_eo =
          fuzz::WriteScratch("eo.txt", "1, 0, 0, 100, 0, 0, 0\n2, 20, 0, 100, 0, 0, 0\n");
      o.marks = fuzz::WriteScratch("marks.txt", text);
      (void)UsableImportedBlock(ImportDbat(o), o.marks);
    } else {
      OdmImportOptions o;
      static const calib::Camera camera = calib::ParseCamera(
          LoadYamlText("pixel_size_mm: 0.004\nformat_px: [6000, 4000]\ninterior: {c: 24}\n", "c"),
          "c");
      o.camera = camera;
      o.gcp_list = fuzz::WriteScratch("gcp_list.txt", text);
      (void)ImportOdmGcpList(o);
    }
  });
  return 0;
}
