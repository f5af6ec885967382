// record/replay: re-emits the recorded outputs of one module (docs/recording.md), in place of
// that module: `vrflow replay` gives it the module's id and ports. Iteration k sends the
// messages the module sent in its iteration k, byte for byte (stamps included; only the send
// time is new). pace: recorded (the recorded arrival times), fast (as fast as consumers take
// them), step (one iteration per message on its beginIt input).
#include <chrono>
#include <cstdio>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "vrflow/base/echo.hpp"
#include "vrflow/message/reader.hpp"
#include "vrflow/module/module.hpp"
#include "vrflow/module/start.hpp"
#include "vrflow/record/reader.hpp"

namespace {

// The records of a recording in file order, a chunk at a time.
class RecordStream {
 public:
  explicit RecordStream(vrflow::record::RecordingReader& reader) : reader_(reader) {}
  // The next record, or nullptr at the end; valid until the next call of next(). Errors end
  // the stream with error() set.
  const vrflow::record::RecordView* peek() {
    while (at_ >= records_.size()) {
      if (chunk_ >= reader_.chunks().size()) return nullptr;
      auto records = reader_.readChunk(chunk_++);
      if (!records) {
        error_ = records.error().message;
        chunk_ = reader_.chunks().size();
        return nullptr;
      }
      records_ = std::move(*records);
      at_ = 0;
    }
    return &records_[at_];
  }
  void pop() { ++at_; }
  const std::string& error() const { return error_; }

 private:
  vrflow::record::RecordingReader& reader_;
  std::vector<vrflow::record::RecordView> records_;
  std::size_t at_ = 0;
  std::size_t chunk_ = 0;
  std::string error_;
};

// The names listed in a space-separated parameter.
std::vector<std::string> wordsOf(const std::string& text) {
  std::vector<std::string> words;
  std::istringstream in(text);
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

std::string pathOf(const vrflow::Module& module) {
  return module.params().getString("file");
}

}  // namespace

int main() {
  using namespace vrflow;
  constexpr const char* kProgram = "vrflow-record-replay";
  constexpr std::size_t kPorts = 8;
  Module module;
  // The replaced module's inputs and outputs, renamed in0.. and out0.. by `vrflow replay`.
  // What the inputs receive is dropped: they only keep the network's synchronisation.
  std::vector<OutputPort*> outputs;
  for (std::size_t i = 0; i < kPorts; ++i) {
    module.addInput("in" + std::to_string(i));
    outputs.push_back(&module.addOutput("out" + std::to_string(i)));
  }
  const InputPort& beginIt = module.addInput("beginIt");
  if (!initOrReport(module, kProgram)) return 2;
  const auto fail = [&](const std::string& why) {
    std::fprintf(stderr, "%s: module %s: %s\n", kProgram, quotedValue(module.id()).c_str(),
                 why.c_str());
    return 2;
  };
  const std::string pace = module.params().getString("pace");
  if (pace == "step" && !beginIt.connected()) {
    return fail(
        "pace 'step' sends one recorded iteration per message on its beginIt input, "
        "and nothing is connected to it (connect one, or use pace 'fast')");
  }
  auto reader = record::RecordingReader::open(pathOf(module));
  if (!reader) return fail(reader.error().message);
  // Which output each recorded connection of the replayed module goes to.
  std::string replayed = module.params().getString("module");
  if (replayed.empty()) replayed = module.id();
  const std::vector<std::string> ports = wordsOf(module.params().getString("outputs"));
  if (ports.size() > kPorts) return fail("parameter 'outputs': more than 8 ports");
  std::vector<int> outputOf((*reader)->connections().size(), -1);
  std::string recorded;
  for (std::size_t c = 0; c < (*reader)->connections().size(); ++c) {
    const auto& connection = (*reader)->connections()[c];
    recorded += (recorded.empty() ? "" : ", ") + connection.name();
    for (std::size_t p = 0; p < ports.size(); ++p) {
      if (connection.module == replayed && connection.port == ports[p]) {
        outputOf[c] = static_cast<int>(p);
      }
    }
  }
  for (std::size_t p = 0; p < ports.size(); ++p) {
    bool found = false;
    for (std::size_t c = 0; c < outputOf.size(); ++c)
      found = found || outputOf[c] == static_cast<int>(p);
    if (!found) {
      return fail("recording " + quotedValue(pathOf(module)) + " holds no output '" + replayed +
                  "." + ports[p] + "' (it holds: " + recorded + ")");
    }
  }

  RecordStream stream(**reader);
  bool paced = pace == "recorded";
  std::uint64_t firstArrivalNs = 0;
  std::chrono::steady_clock::time_point start;
  bool started = false;
  // Skips the records of other modules; true while one of ours remains.
  const auto nextOurs = [&]() -> const record::RecordView* {
    for (const record::RecordView* r = stream.peek(); r != nullptr; r = stream.peek()) {
      if (outputOf[r->connection] >= 0) return r;
      stream.pop();
    }
    return nullptr;
  };
  while (nextOurs() != nullptr && module.wait()) {
    const std::uint64_t iteration = module.iteration();
    for (const record::RecordView* r = nextOurs(); r != nullptr && r->iteration <= iteration;
         r = nextOurs()) {
      if (paced) {
        if (!started) {
          start = std::chrono::steady_clock::now();
          firstArrivalNs = r->arrivalNs;
          started = true;
        }
        const auto offset = r->arrivalNs > firstArrivalNs ? r->arrivalNs - firstArrivalNs : 0;
        std::this_thread::sleep_until(start + std::chrono::nanoseconds(offset));
      }
      auto view = msg::MessageView::parse(r->message);
      if (!view) return fail(view.error().message);
      auto out = module.newMessage(r->message.size());
      out.builder().setStamps(view->stamps().toStamps());
      out.builder().setStampsOnly(view->stampsOnly());
      out.builder().appendChunks(*view);
      const auto port = static_cast<std::size_t>(outputOf[r->connection]);
      stream.pop();
      if (!module.put(*outputs[port], std::move(out))) break;
    }
  }
  if (!stream.error().empty()) return fail(stream.error());
  return module.exitStatus();
}
