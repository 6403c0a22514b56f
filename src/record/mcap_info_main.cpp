// convoy-mcap FILE.mcap: reads an MCAP file with Convoy's own reader (record/mcap_reader.h,
// the one `convoy replay` and `convoy score` use) and prints what it holds as JSON: whether it
// is complete, its messages per topic, its metadata records' names. A file cut short (a
// killed or starved writer) is read up to its last whole record, with a warning on stderr.
//
// Exit 0: read (complete or cut short); 2: not readable (no such file, not MCAP, a CRC or a
// record that does not match). The C++ side of `python3 -m convoy_mcap` and
// tools/mcap_check; tests/e2e/test_recording_faults.py uses it.
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "record/mcap_reader.h"

int main(int argc, char** argv) {
  if (argc != 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cerr << "usage: convoy-mcap FILE.mcap  (topics, counts and completeness, as JSON)\n";
    return argc == 2 ? 0 : 2;
  }
  try {
    convoy::record::McapReader reader(argv[1]);
    std::map<std::string, uint64_t> topics;
    uint64_t messages = 0;
    convoy::record::McapMessage m;
    while (reader.next(&m)) {
      ++topics[reader.channels().at(m.channel).topic];
      ++messages;
    }
    nlohmann::json out = {{"file", argv[1]},
                          {"complete", reader.complete()},
                          {"incomplete", reader.incomplete_reason()},
                          {"library", reader.library()},
                          {"messages", messages},
                          {"topics", topics}};
    out["metadata"] = nlohmann::json::array();
    for (const auto& [name, _] : reader.metadata()) out["metadata"].push_back(name);
    if (!reader.complete())
      std::cerr << "warning: " << argv[1]
                << ": incomplete recording: " << reader.incomplete_reason() << "; read its "
                << messages << " messages up to there\n";
    std::cout << out.dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
}
