-- A door (here, the window's shutter) on a hinge. It opens with F once the
-- player holds the key (key.lua sends "got_key").
property("open_degrees", -105)
property("seconds", 1.2)

function init(self)
  self.has_key = false
  self.angle = 0       -- degrees, 0 = shut
  self.target = 0
end

function on_message(self, id, msg)
  if id == "got_key" then
    self.has_key = true
    log.info("the door can be opened now: press F")
  end
end

function update(self, dt)
  if input.pressed("F") then
    if not self.has_key then
      log.warn("the door is locked: find the key")
    else
      self.target = (self.target == 0) and self.open_degrees or 0
      log.info(self.target == 0 and "closing the door" or "opening the door")
    end
  end
  if self.angle ~= self.target then
    local step = math.abs(self.open_degrees) / self.seconds * dt
    local d = self.target - self.angle
    self.angle = (math.abs(d) <= step) and self.target or self.angle + step * (d > 0 and 1 or -1)
    self.entity.transform:set_rotation({0, math.rad(self.angle), 0})
  end
end
