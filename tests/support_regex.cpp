// The tests' regular expressions (support.hpp), in one file: <regex> takes about 20 s to compile
// under the sanitizers, 7 s in Release, for every file that includes it.
#include <regex>

#include "support.hpp"

namespace globemesh::test {

bool regex_search(const std::string& text, const std::string& pattern, std::vector<std::string>* groups) {
    std::smatch m;
    if (!std::regex_search(text, m, std::regex(pattern))) return false;
    if (groups) {
        groups->clear();
        for (const auto& g : m) groups->push_back(g.str());
    }
    return true;
}

bool regex_match(const std::string& text, const std::string& pattern, std::vector<std::string>* groups) {
    std::smatch m;
    if (!std::regex_match(text, m, std::regex(pattern))) return false;
    if (groups) {
        groups->clear();
        for (const auto& g : m) groups->push_back(g.str());
    }
    return true;
}

std::vector<std::string> regex_all(const std::string& text, const std::string& pattern, int group) {
    std::vector<std::string> out;
    const std::regex re(pattern);
    for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
        out.push_back((*it)[group].str());
    return out;
}

std::string regex_replace(const std::string& text, const std::string& pattern, const std::string& with) {
    return std::regex_replace(text, std::regex(pattern), with);
}

} // namespace globemesh::test
