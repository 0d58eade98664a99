// The tests' regular expressions (support.hpp), in one file: <regex> takes about 20 s to compile
// under the sanitizers, 7 s in Release, for every file that includes it.
#include <regex>

#include "support.hpp"

namespace globemesh::test {

namespace {

// The groups of a match into `groups` when it was found.
bool take(bool found, const std::smatch &m, std::vector<std::string> *groups) {
    if (found && groups) {
        groups->clear();
        for (const auto &g : m)
            groups->push_back(g.str());
    }
    return found;
}

} // namespace

bool regex_search(const std::string &text, const std::string &pattern,
                  std::vector<std::string> *groups) {
    std::smatch m;
    return take(std::regex_search(text, m, std::regex(pattern)), m, groups);
}

bool regex_match(const std::string &text, const std::string &pattern,
                 std::vector<std::string> *groups) {
    std::smatch m;
    return take(std::regex_match(text, m, std::regex(pattern)), m, groups);
}

std::vector<std::string> regex_all(const std::string &text, const std::string &pattern, int group) {
    std::vector<std::string> out;
    const std::regex re(pattern);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator();
         ++it)
        out.push_back((*it)[group].str());
    return out;
}

std::string regex_replace(const std::string &text, const std::string &pattern,
                          const std::string &with) {
    return std::regex_replace(text, std::regex(pattern), with);
}

} // namespace globemesh::test
