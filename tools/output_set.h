// The outputs of one command written as a set (issue 37 class 8): every part is written into a
// staging folder inside the output folder, and Commit() moves the parts into place only once all
// of them were written. When any part fails (or the set is destroyed without Commit), the staging
// folder is removed and the previous set in the output folder is left exactly as it was; an output
// folder the set created itself is removed again when it stays empty.
#pragma once

#include <string>
#include <vector>

namespace aerocal::tools {

class OutputSet {
 public:
  /// `out_folder`: the folder the parts end in (created when missing). Throws InputError when it
  /// cannot be created.
  explicit OutputSet(std::string out_folder);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// The staging folder (write the parts here, under their final names).
  const std::string& staging() const { return staging_; }
  /// The staged path of part `name` (a plain file name).
  std::string Staged(const std::string& name) const;
  /// The final path of part `name`.
  std::string Final(const std::string& name) const;

  /// Moves the staged `parts` into the output folder (a part's previous file is replaced; should a
  /// rename fail, the parts already moved are put back and InputError is thrown). Parts of the
  /// previous set named in `obsolete` that this set does not write are removed, so the folder never
  /// holds parts of two different sets. Throws InputError when a part was not staged.
  void Commit(const std::vector<std::string>& parts, const std::vector<std::string>& obsolete = {});

 private:
  std::string out_, staging_;
  bool created_out_ = false, committed_ = false;
};

}  // namespace aerocal::tools
