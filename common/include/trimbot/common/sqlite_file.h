#pragma once
// A small layer over SQLite for the project's data files (the visual map, the cutting plans): a
// file is written whole, in one transaction, into a temporary beside it and renamed over the old
// one (never half-written), and opened read-only to load; a `meta` table of key-value text says
// what the file is (its format name, version, what it was made for). SQL failures are SqlError,
// which the loaders turn into InputError naming the file.
#include <sqlite3.h>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace trimbot::sqlite {

class SqlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

using Database = std::unique_ptr<sqlite3, int (*)(sqlite3*)>;
using Statement = std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)>;

void Exec(sqlite3* db, const std::string& sql);
Statement Prepare(sqlite3* db, const std::string& sql);
// Runs a statement that returns no rows and resets it for the next bindings.
void Step(sqlite3* db, sqlite3_stmt* statement);

// Creates the meta table with these pairs; reads one value (SqlError when missing).
void WriteMeta(sqlite3* db, const std::vector<std::pair<std::string, std::string>>& pairs);
std::string Meta(sqlite3* db, const std::string& key);

// Writes `path` anew: `write(db)` in one transaction into a temporary beside it, renamed over
// `path` when it succeeded. std::runtime_error naming the file otherwise (nothing left behind).
void WriteAtomically(const std::string& path, const std::function<void(sqlite3*)>& write);

// Opens an existing file read-only; InputError naming the file when it is missing or cannot be
// opened (`what`: "map file", "cutting plan database", ... for the message).
Database OpenReadOnly(const std::string& path, const std::string& what);

}  // namespace trimbot::sqlite
