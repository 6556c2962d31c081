#include "trimbot/common/sqlite_file.h"

#include <unistd.h>

#include <filesystem>

#include "trimbot/common/input_error.h"

namespace trimbot::sqlite {

void Exec(sqlite3* db, const std::string& sql) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string message = error ? error : "unknown error";
    sqlite3_free(error);
    throw SqlError(message + " in: " + sql.substr(0, 60));
  }
}

Statement Prepare(sqlite3* db, const std::string& sql) {
  sqlite3_stmt* statement = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
    throw SqlError(std::string(sqlite3_errmsg(db)) + " in: " + sql.substr(0, 60));
  }
  return Statement(statement, &sqlite3_finalize);
}

void Step(sqlite3* db, sqlite3_stmt* statement) {
  if (sqlite3_step(statement) != SQLITE_DONE) throw SqlError(sqlite3_errmsg(db));
  sqlite3_reset(statement);
}

void WriteMeta(sqlite3* db, const std::vector<std::pair<std::string, std::string>>& pairs) {
  Exec(db, "CREATE TABLE meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);");
  Statement meta = Prepare(db, "INSERT INTO meta VALUES(?, ?)");
  for (const auto& [key, value] : pairs) {
    sqlite3_bind_text(meta.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(meta.get(), 2, value.c_str(), -1, SQLITE_TRANSIENT);
    Step(db, meta.get());
  }
}

std::string Meta(sqlite3* db, const std::string& key) {
  Statement statement = Prepare(db, "SELECT value FROM meta WHERE key = ?");
  sqlite3_bind_text(statement.get(), 1, key.c_str(), -1, SQLITE_TRANSIENT);
  if (sqlite3_step(statement.get()) != SQLITE_ROW) throw SqlError("no '" + key + "' in the meta table");
  return reinterpret_cast<const char*>(sqlite3_column_text(statement.get(), 0));
}

void WriteAtomically(const std::string& path, const std::function<void(sqlite3*)>& write) {
  const std::string temporary = path + ".tmp" + std::to_string(::getpid());
  std::filesystem::remove(temporary);
  sqlite3* raw = nullptr;
  if (sqlite3_open(temporary.c_str(), &raw) != SQLITE_OK) {
    sqlite3_close(raw);
    throw std::runtime_error(path + ": cannot create the file");
  }
  Database db(raw, &sqlite3_close);
  try {
    Exec(db.get(), "BEGIN");
    write(db.get());
    Exec(db.get(), "COMMIT");
  } catch (const SqlError& e) {
    db.reset();
    std::filesystem::remove(temporary);
    throw std::runtime_error(path + ": writing failed: " + e.what());
  }
  db.reset();
  std::filesystem::rename(temporary, path);
}

Database OpenReadOnly(const std::string& path, const std::string& what) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path, what + " not found");
  sqlite3* raw = nullptr;
  if (sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(raw);
    throw InputError(path, "cannot open the " + what);
  }
  return Database(raw, &sqlite3_close);
}

}  // namespace trimbot::sqlite
