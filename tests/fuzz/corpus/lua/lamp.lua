-- A lamp switched on and off with a key (E by default).
property("key", "E")

function update(self, dt)
  if input.pressed(self.key) then
    local light = self.entity.light
    light:set_enabled(not light:is_enabled())
    log.info("lamp " .. (light:is_enabled() and "on" or "off"))
  end
end
