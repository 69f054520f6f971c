// The outputs of one command written as a set (issue 37 class 8): every part is written into a
// staging folder inside the folder it ends in, and Commit() moves the parts into place only once
// all of them were written. When any part fails (or the set is destroyed without Commit), the
// staging folders are removed and the previous set is left exactly as it was; an output folder
// the set created itself is removed again when it stays empty. A part is a file or a folder
// (flight's certificate/); parts may lie in several folders (rig stitch's JSON and its stitched
// images, camera convert's OUT and --report): each folder gets its own staging folder, so every
// move is a rename within one file system.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace aerocal::tools {

class OutputSet {
 public:
  /// `out_folder`: the folder the named parts end in (created when missing). Throws InputError
  /// when it cannot be created.
  explicit OutputSet(std::string out_folder);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// The staging folder of the output folder (write the parts here, under their final names).
  const std::string& staging() const { return staging_; }
  /// The staged path of part `name` (a plain file name) of the output folder.
  std::string Staged(const std::string& name) const;
  /// The final path of part `name` of the output folder.
  std::string Final(const std::string& name) const;
  /// A part at `final_path` in any folder (created when missing): its staged path. The part is
  /// committed with the named ones; staging it twice is a LogicError.
  std::string StagePath(const std::string& final_path);

  /// Moves the staged `parts` of the output folder and every part of StagePath into place (a
  /// part's previous file or folder is replaced; should a rename fail, the parts already moved
  /// are put back and InputError is thrown). Parts of the previous set named in `obsolete` that
  /// this set does not write are removed, so the folder never holds parts of two different sets.
  /// Throws InputError when a part was not staged.
  void Commit(const std::vector<std::string>& parts, const std::vector<std::string>& obsolete = {});

 private:
  // The staging folder of `folder`, created on first use.
  const std::string& StagingOf(const std::string& folder);

  std::string out_, staging_;
  std::map<std::string, std::string> staging_of_;  // output folder -> its staging folder
  std::vector<std::string> created_;               // output folders this set created
  std::vector<std::string> elsewhere_;             // final paths staged through StagePath
  bool committed_ = false;
};

/// ConfigError naming `option` when `path` is the file `other` names (`other_name`: OUT, IN, an
/// option): an output that would replace an input or another output of the same command. Paths
/// are compared after resolving `.`, `..` and symbolic links, and as hard links where both exist.
void CheckDistinctPath(const std::string& path,
                       const std::string& option,
                       const std::string& other,
                       const std::string& other_name);

}  // namespace aerocal::tools
