#pragma once
// report.html: the one page of a result folder that people open and send on. It is built from the
// folder's own files (summary.json of a batch, sweep.json, comparison.json, tune.json, suite.json,
// the trials' events.csv, the PNG plots beside them), so `trimbot report DIR`
// regenerates it from any folder and a batch writes it the same way as its last step. (The
// trials' figures come from summary.json, which holds their results; their folders give the
// plots, events and files.)
//
// The page is self-contained: inline CSS, images by relative path, no script but one that marks
// images that failed to load (data-broken-images on <body>, and a console error each), no network.
// It holds nothing that changes from run to run but what the files hold (no clock, no paths of this
// machine beyond those the files name), so two runs of one seed give the same page apart from the
// wall-clock figures of timing.json.
#include <string>

namespace trimbot::scenarios {

// Writes DIR/report.html atomically. Throws InputError naming the file when DIR holds none of the
// result files above, or one of them (or timing.json) is truncated or malformed; nothing is
// written then.
void WriteHtmlReport(const std::string& dir);

// The page WriteHtmlReport writes, without writing it.
std::string HtmlReport(const std::string& dir);

}  // namespace trimbot::scenarios
