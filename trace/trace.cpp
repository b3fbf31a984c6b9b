// Placeholder translation unit so the trace library exists before its first node lands.
namespace speculum::trace {}
