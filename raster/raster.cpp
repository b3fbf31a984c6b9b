// Placeholder translation unit so the raster library exists before its first node lands.
namespace speculum::raster {}
