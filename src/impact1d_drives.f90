!> Prescribed motion of the ground end of a contact or element (docs/method.md section 11):
!> w(t) = v t + amp sin(omega t + phase) + table(t), each term present only when named (the
!> table: piecewise linear between its corners, held at its ends, as a force table). The gap of a row
!> with a moving ground end is x_b - w(t) - limit, a spring to a moving anchor stretches by
!> x_b - w(t) - rest; w and its derivatives are evaluated exactly here (never interpolated),
!> so that the engine's gaps, impacts and held rows see the motion the user wrote.
module impact1d_drives
  use impact1d_kinds, only: wp
  use impact1d_forcing, only: table_type, table_value, table_slope, segment
  use impact1d_state, only: product_error
  implicit none
  private
  public :: drive_type

  !> The scene's moving grounds, one per record that moves its ground end (nd of them).
  type :: drive_type
    integer :: n = 0                             !< nd (0: every ground stays still)
    real(wp), allocatable :: v(:)                !< (nd) constant velocity, m/s
    real(wp), allocatable :: amp(:), omega(:), phase(:)   !< (nd) the sine: m, rad/s (0: none), rad
    logical :: polynomial = .true.               !< no drive has a sine: w is piecewise linear in t
    !> (nd) the drive's table (ground_table), when has_table: its velocity jumps at the
    !> corners, which are stops (next_corner); w' there is the slope after the corner
    logical, allocatable :: has_table(:)
    type(table_type), allocatable :: table(:)
    logical, allocatable :: varies(:)            !< (nd) a sine or a table: add_varying's terms
    logical :: tables = .false.                  !< some drive has a table
    !> add_varying, called through a pointer: the compiler then keeps it out of position and
    !> velocity, which stay small enough to be inlined (see add_varying)
    procedure(add_varying), pointer, nopass :: varying => add_varying
  contains
    procedure :: add
    procedure :: position
    procedure :: position_parts
    procedure :: rounded_part
    procedure :: displacement
    procedure :: displacement_parts
    procedure :: velocity
    procedure :: acceleration
    procedure :: jerk
    procedure :: next_corner
    procedure :: before_corner
  end type drive_type

contains

  !> One more drive (v, amp, omega, phase, and its table when given); its index is self%n after.
  pure subroutine add(self, v, amp, omega, phase, table)
    class(drive_type), intent(inout) :: self
    real(wp), intent(in) :: v, amp, omega, phase
    type(table_type), intent(in), optional :: table
    type(table_type) :: none
    if (.not. allocated(self%v)) allocate(self%v(0), self%amp(0), self%omega(0), self%phase(0), &
      self%has_table(0), self%table(0), self%varies(0))
    self%v = [self%v, v]
    self%amp = [self%amp, amp]
    self%omega = [self%omega, omega]
    self%phase = [self%phase, phase]
    self%has_table = [self%has_table, present(table)]
    self%varies = [self%varies, omega /= 0.0_wp .or. present(table)]
    if (present(table)) then
      self%table = [self%table, table]
    else
      self%table = [self%table, none]
    end if
    self%tables = any(self%has_table)
    self%n = self%n + 1
    self%polynomial = self%polynomial .and. omega == 0.0_wp
  end subroutine add

  !> w_d(t).
  pure real(wp) function position(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = self%v(d) * t
    if (self%varies(d)) w = self%varying(self, d, t, 0, w)
  end function position

  !> w plus drive d's sine and table terms at t, of w (order 0) or of w' (1), in that order.
  !> (Apart from position and velocity, and called through a pointer (varying), so that
  !> those stay small enough to be inlined: with the table's terms inside them they no
  !> longer were, and input/burridge_knopoff.nml's ten blocks dragged by anchors at
  !> constant speed took 15% more instructions (154.0 M -> 177.5 M, callgrind, 2 s of the
  !> CLI's run); a direct call, subroutine or pure function, was inlined back (175.7 M).
  !> The pointer's cost, 159.0 M (+3.2%): the compiler must assume the call writes memory,
  !> so the callers' element loops reloaded the scene's array descriptors at each element
  !> where they kept them in registers around sin (they now take the element records as
  !> explicit-shape arrays: impact1d_elements' moving_forces, 142.6 M). A function with w
  !> by value: with w intent(inout) every call also stored w first, 159.5 M.)
  pure real(wp) function add_varying(self, d, t, order, w_in) result(w)
    type(drive_type), intent(in) :: self
    integer, intent(in) :: d, order
    real(wp), intent(in) :: t
    real(wp), value :: w_in
    w = w_in
    if (self%omega(d) /= 0.0_wp) then
      if (order == 0) then
        w = w + self%amp(d) * sin(self%omega(d) * t + self%phase(d))
      else
        w = w + self%amp(d) * self%omega(d) * cos(self%omega(d) * t + self%phase(d))
      end if
    end if
    if (self%tables) w = w + table_part(self, d, t, order)
  end function add_varying

  !> w_d at the clock t + t_lo as hi + lo: v t without rounding (Dekker's product), the
  !> clock's low part w' t_lo and the sine in lo. A body put on the ground (snapped) is then
  !> where the step, which moves a body held to it by the clock's exact increments, took it:
  !> with w rounded, each snap moved a held body by up to an ulp of its position, against
  !> the bodies in flight beside it, and a ground moving at constant speed did not give the
  !> still ground's rattle (two balls came to rest on a floor in 551 events, on the same
  !> floor seen from a moving frame in 346,946).
  pure subroutine position_parts(self, d, t, t_lo, hi, lo)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, t_lo
    real(wp), intent(out) :: hi, lo
    call exact_product(self%v(d), t, hi, lo)
    lo = lo + self%velocity(d, t) * t_lo
    if (self%omega(d) /= 0.0_wp) lo = lo + self%amp(d) * sin(self%omega(d) * t + self%phase(d))
    if (self%tables) lo = lo + table_part(self, d, t, 0)
  end subroutine position_parts

  !> a b = p + e exactly (p rounded, e its error: impact1d_state's product_error).
  pure subroutine exact_product(a, b, p, e)
    real(wp), intent(in) :: a, b
    real(wp), intent(out) :: p, e
    p = a * b
    e = product_error(a, b)
  end subroutine exact_product

  !> The size of what position_parts rounds in w_d(t): the sine's |amp sin(omega t + phase)|
  !> (v t is exact there), for a gap's rounding level. Counting all of |w| made a floor
  !> moving at constant speed close gaps a still floor leaves open (2.5e-15 m at w = 0.7 m).
  pure real(wp) function rounded_part(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = abs(self%amp(d) * sin(self%omega(d) * t + self%phase(d)))
    if (self%tables) w = w + abs(table_part(self, d, t, 0))
  end function rounded_part

  !> w_d(t + h) - w_d(t), accurate however small h is against t (a difference of positions
  !> would round a step below the clock's ulp to 0): sin(a + c) - sin(a) = 2 cos(a + c/2)
  !> sin(c/2).
  pure real(wp) function displacement(self, d, t, h) result(dw)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    dw = self%v(d) * h
    if (self%omega(d) /= 0.0_wp) dw = dw + 2.0_wp * self%amp(d) * cos(self%omega(d) * (t + 0.5_wp * h) + &
      self%phase(d)) * sin(0.5_wp * self%omega(d) * h)
    if (self%tables) dw = dw + table_displacement(self, d, t, h)
  end function displacement

  !> displacement as hi + lo, its v h without rounding (exact_product) where the drive is v t
  !> alone (no sine, no table): a body held to a ground moving at constant speed, moved by the clock's exact increments, stays on w(t)
  !> as position_parts forms it (with v h rounded it drifted off by 4e-18 m in 0.1 s, and a
  !> ball resting on a floor at 0.8 m/s was not closed on it when another ball landed).
  pure subroutine displacement_parts(self, d, t, h, hi, lo)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    real(wp), intent(out) :: hi, lo
    hi = self%displacement(d, t, h)
    lo = 0.0_wp
    if (self%omega(d) /= 0.0_wp) return
    if (self%tables) then
      if (self%has_table(d)) return
    end if
    call exact_product(self%v(d), h, hi, lo)
  end subroutine displacement_parts

  !> Drive d's table at t: its value (order 0) or its slope from t on (1); 0 without one.
  pure real(wp) function table_part(self, d, t, order) result(w)
    type(drive_type), intent(in) :: self
    integer, intent(in) :: d, order
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (.not. self%has_table(d)) return
    if (order == 0) then
      w = table_value(self%table(d), t)
    else
      w = table_slope(self%table(d), segment(self%table(d)%t, t))
    end if
  end function table_part

  !> table(t + h) - table(t) of drive d (0 without one): the segment's slope times h within
  !> one segment (a step never crosses a corner: corners are stops), so that a step below
  !> the clock's ulp counts.
  pure real(wp) function table_displacement(self, d, t, h) result(dw)
    type(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    integer :: k
    dw = 0.0_wp
    if (.not. self%has_table(d)) return
    associate (table => self%table(d))
      k = segment(table%t, t)
      if (k == size(table%t)) then
        dw = 0.0_wp
      else if (t + h <= table%t(k + 1)) then
        dw = table_slope(table, k) * h
      else
        dw = table_value(table, t + h) - table_value(table, t)
      end if
    end associate
  end function table_displacement

  !> w_d'(t).
  pure real(wp) function velocity(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = self%v(d)
    if (self%varies(d)) w = self%varying(self, d, t, 1, w)
  end function velocity

  !> w_d''(t).
  pure real(wp) function acceleration(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = -self%amp(d) * self%omega(d)**2 * sin(self%omega(d) * t + self%phase(d))
  end function acceleration

  !> w_d'''(t): which way the acceleration goes (a held row's force exactly at zero).
  pure real(wp) function jerk(self, d, t) result(w)
    class(drive_type), intent(in) :: self
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    w = 0.0_wp
    if (self%omega(d) /= 0.0_wp) w = -self%amp(d) * self%omega(d)**3 * cos(self%omega(d) * t + self%phase(d))
  end function jerk

  !> The first table corner strictly after t (huge if none): steps end there exactly, where
  !> a table's velocity jumps (as force tables' corners: impact1d_forcing's next_breakpoint).
  pure real(wp) function next_corner(self, t) result(t_next)
    class(drive_type), intent(in) :: self
    real(wp), intent(in) :: t
    integer :: d, k
    t_next = huge(1.0_wp)
    if (.not. self%tables) return
    do d = 1, self%n
      if (.not. self%has_table(d)) cycle
      k = segment(self%table(d)%t, t) + 1
      if (k <= size(self%table(d)%t)) t_next = min(t_next, self%table(d)%t(k))
    end do
  end function next_corner

  !> The time at which a step from t0 ending at t1 sees the drives at its end: t1, or the
  !> float before a corner in (t0, t1] (the step ends there: velocity takes the slope after
  !> a corner, the step's end the one before it; w moves by the slope times an ulp).
  pure real(wp) function before_corner(self, t0, t1) result(t)
    class(drive_type), intent(in) :: self
    real(wp), intent(in) :: t0, t1
    real(wp) :: corner
    t = t1
    if (.not. self%tables) return
    corner = self%next_corner(t0)
    if (corner <= t1) t = max(t0, nearest(corner, -1.0_wp))
  end function before_corner
end module impact1d_drives
