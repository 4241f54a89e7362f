// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "output_transaction.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>

namespace pointform::cli {
namespace {

/// A name beside `target` that no file has: "<target>.pf-<pid>-<n><extension of target>".
std::filesystem::path unused_name_beside(const std::filesystem::path& target, const char* kind)
{
    static std::atomic<unsigned> counter{0};
    for (;;)
    {
        char tag[64];
        std::snprintf(tag, sizeof tag, ".pf-%s-%ld-%u", kind, static_cast<long>(::getpid()),
                      counter.fetch_add(1));
        std::filesystem::path name = target;
        name += tag;
        name += target.extension();
        std::error_code ec;
        if (!std::filesystem::exists(std::filesystem::symlink_status(name, ec)))
        {
            return name;
        }
    }
}

void remove_quietly(const std::filesystem::path& path)
{
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
}

} // namespace

OutputTransaction::~OutputTransaction()
{
    if (committed_)
    {
        return;
    }
    for (const Staged& s : staged_)
    {
        remove_quietly(s.temp);
    }
}

std::filesystem::path OutputTransaction::reserve(const std::filesystem::path& target)
{
    if (committed_)
    {
        throw Error("output transaction: staging after commit");
    }
    std::error_code ec;
    if (std::filesystem::is_directory(target, ec))
    {
        throw IoError(target, "cannot write the file: it is a directory");
    }
    const std::filesystem::path absolute = std::filesystem::weakly_canonical(target, ec);
    for (const Staged& s : staged_)
    {
        std::error_code ec2;
        if (s.target == target ||
            (!ec && std::filesystem::weakly_canonical(s.target, ec2) == absolute && !ec2))
        {
            throw InvalidInput("the same file is given for two outputs: " + target.string());
        }
    }
    staged_.push_back({target, unused_name_beside(target, "tmp")});
    return staged_.back().temp;
}

void OutputTransaction::discard_last()
{
    remove_quietly(staged_.back().temp);
    staged_.pop_back();
}

std::string OutputTransaction::strip_path(const IoError& e, const std::filesystem::path& temp)
{
    std::string what = e.what();
    const std::string prefix = temp.string() + ": ";
    if (what.compare(0, prefix.size(), prefix) == 0)
    {
        what.erase(0, prefix.size());
    }
    return what;
}

void OutputTransaction::commit()
{
    if (committed_)
    {
        return;
    }
    // Keep each existing target reachable under a second name, so that a failed rename can put
    // back the ones already replaced.
    std::vector<std::filesystem::path> backups(staged_.size());
    for (std::size_t i = 0; i < staged_.size(); ++i)
    {
        std::error_code ec;
        if (std::filesystem::is_regular_file(staged_[i].target, ec))
        {
            const std::filesystem::path backup = unused_name_beside(staged_[i].target, "old");
            if (::link(staged_[i].target.c_str(), backup.c_str()) == 0)
            {
                backups[i] = backup;
            }
        }
    }
    auto drop_backups = [&] {
        for (const std::filesystem::path& b : backups)
        {
            if (!b.empty())
            {
                remove_quietly(b);
            }
        }
    };
    for (std::size_t i = 0; i < staged_.size(); ++i)
    {
        if (::rename(staged_[i].temp.c_str(), staged_[i].target.c_str()) == 0)
        {
            continue;
        }
        const std::string reason = std::strerror(errno);
        for (std::size_t j = i; j-- > 0;)
        {
            if (!backups[j].empty())
            {
                if (::rename(backups[j].c_str(), staged_[j].target.c_str()) == 0)
                {
                    backups[j].clear();
                }
            }
            else
            {
                remove_quietly(staged_[j].target); // it did not exist before
            }
        }
        for (std::size_t j = i; j < staged_.size(); ++j)
        {
            remove_quietly(staged_[j].temp);
        }
        drop_backups();
        committed_ = true; // nothing staged is left to remove
        throw IoError(staged_[i].target, "cannot move the file into place: " + reason);
    }
    drop_backups();
    committed_ = true;
}

} // namespace pointform::cli
