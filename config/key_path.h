// Documents built in memory, located by key path: a Python dict written as JSON text (JSON is
// YAML) for the ordinary text readers, whose diagnostics then name the key path of the node where
// a file's name its line and column.
//
//   std::string text = key_path_document(json.dump(1));       // one node per line
//   StatusOr<link::LinkSpec> s = link::read_link_spec_text(text, "spec");
//   // "cable.lenght: error: unknown key 'cable.lenght' in 'cable' (known keys: ...)"
//   // "stimulus.frames[1]: error: ...", and for the whole document "spec: error: ..."
//
// The document's first line marks it, so the mark travels with the text: documents parsed again
// from it (a sweep's base per point, a pack's hops) keep key paths. YamlDoc::loc asks
// key_path_at for every location in such a document. One node per line, as nlohmann's dump(1)
// writes it, keeps every node (a map under a key, the key itself, list items) at a position of its
// own, so each key path is exact.
#pragma once

#include <optional>
#include <string>

#include "base/source_loc.h"

namespace isolink::config {

// The text to read: the mark, then json_text.
std::string key_path_document(const std::string& json_text);
// Whether the file holds such a document (its first line is the mark).
bool is_key_path_document(const SourceFile& file);
// The key path of the node that starts at line:col (1-based) of such a document: "cable.length",
// "stimulus.frames[1]", "" for the root; nullopt when no node starts there.
std::optional<std::string> key_path_at(const SourceFile& file, int line, int col);

}  // namespace isolink::config
