-- A ball with a few lines of kinematics: gravity, bounces off the floor and
-- the room's walls, rolling friction, and a roll that matches the distance
-- travelled. The player pushes it by walking into it and throws it with G.
property("radius", 0.25)
property("throw_key", "G")
property("room_min_x", -3.05)
property("room_max_x", 2.95)
property("room_min_z", -2.55)
property("room_max_z", 2.55)

function init(self)
  self.vx, self.vy, self.vz = 0, 0, 0
  self.camera = scene.find("Camera")
end

local function bounce(p, v, lo, hi, keep)
  if p < lo then return lo, -v * keep end
  if p > hi then return hi, -v * keep end
  return p, v
end

function update(self, dt)
  local t = self.entity.transform
  local x, y, z = t:get_position()
  local cx, cy, cz = self.camera.transform:get_world_position()
  local dx, dz = x - cx, z - cz
  local flat = math.sqrt(dx * dx + dz * dz)
  if flat < 0.6 and flat > 1e-3 then             -- walked into: pushed away
    self.vx, self.vz = self.vx + 6 * dt * dx / flat, self.vz + 6 * dt * dz / flat
  end
  if input.pressed(self.throw_key) and flat < 3.5 then
    local fx, fy, fz = self.camera.transform:get_forward()
    self.vx, self.vy, self.vz = 3.5 * fx, 2.5, 3.5 * fz
    log.info("ball thrown")
  end
  self.vy = self.vy - 9.81 * dt
  x, y, z = x + self.vx * dt, y + self.vy * dt, z + self.vz * dt
  y, self.vy = bounce(y, self.vy, self.radius, 100, 0.45)
  x, self.vx = bounce(x, self.vx, self.room_min_x + self.radius, self.room_max_x - self.radius, 0.6)
  z, self.vz = bounce(z, self.vz, self.room_min_z + self.radius, self.room_max_z - self.radius, 0.6)
  if y <= self.radius + 1e-3 then                 -- on the floor: rolling friction
    local keep = math.max(0, 1 - 0.9 * dt)
    self.vx, self.vz = self.vx * keep, self.vz * keep
    if math.abs(self.vy) < 0.2 then self.vy = 0 end
    if self.vx * self.vx + self.vz * self.vz < 1e-4 and self.vy == 0 then
      -- At rest: leave the transform alone, so nothing is re-lit and the
      -- progressive reference can accumulate.
      self.vx, self.vz = 0, 0
      return
    end
  end
  t:set_position(x, y, z)
  local speed = math.sqrt(self.vx * self.vx + self.vz * self.vz)
  if speed > 1e-3 then                            -- roll about the axis across the motion
    t:rotate({self.vz / speed, 0, -self.vx / speed}, speed * dt / self.radius)
  end
end
