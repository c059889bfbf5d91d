// The <simulation> element: each attribute is a setting (settings.cpp), applied
// before the overrides of the YAML config, --set and ROS parameters.
#include "scene_build.hpp"

namespace nscd {

void readSimulation(SceneBuild& sb, const std::vector<SettingOverride>& overrides) {
  const auto& sims = sb.nscd["simulation"];
  if (sims.size() > 1)
    sb.c.fail(sims[1]->GetLineNum(), "more than one <simulation> element (first at line " +
                                       std::to_string(sims[0]->GetLineNum()) + ")");
  for (const XMLElement* e : sims) {
    checkChildren(sb.c, e, vocabularyOf("simulation").children);
    const std::string where = sb.c.file + ":" + std::to_string(e->GetLineNum());
    for (const XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
      applySetting(sb.m.settings, SettingOverride{a->Name(), a->Value(), where});
  }
  for (const SettingOverride& o : overrides) applySetting(sb.m.settings, o);
}

}  // namespace nscd
